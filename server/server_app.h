// The server's life cycle: listen, load the model, serve, reload on SIGHUP, drain on SIGTERM.
#pragma once

#include "server/config.h"

namespace tod::server {

// Blocks SIGTERM/SIGINT/SIGHUP in the calling thread (and so in every thread started after);
// call first in main so that RunServer can take them with sigwait.
void BlockServerSignals();

// Runs until SIGTERM or SIGINT; returns the process exit code (0 after a clean drain, 1 when
// start-up failed, e.g. a port in use or a broken model bundle).
int RunServer(const ServerConfig& config);

}  // namespace tod::server

// tod_server: the obstacle discovery service (gRPC + REST on one bounded worker pool).
#include <CLI/CLI.hpp>
#include <cstdlib>
#include <iostream>
#include <map>
#include <string>

#include "core/base/heap_tuning.h"
#include "server/config.h"
#include "server/logging.h"
#include "server/server_app.h"

int main(int argc, char** argv) {
  tod::server::BlockServerSignals();
  tod::RetainLargeAllocations();  // workers run the pipeline frame after frame
  tod::ShareOneHeapArena();       // ... and one worker reuses what another freed
  CLI::App app{"tod_server: tiny obstacle discovery over gRPC and REST"};
  std::map<std::string, std::string> flags;
  std::string config_file;
  app.add_option("--config", config_file,
                 "JSON file of settings (keys as the flags with '_'); flags and TOD_* win");
  // Every setting is taken as text here and parsed once, in one place, with the file and the
  // environment (server/config.cc).
  std::map<std::string, std::string> values;
  for (const tod::server::SettingSpec& spec : tod::server::SettingSpecs()) {
    app.add_option("--" + spec.flag, values[spec.key], spec.help + " [env " + spec.env + "]");
  }
  CLI11_PARSE(app, argc, argv);
  for (const tod::server::SettingSpec& spec : tod::server::SettingSpecs()) {
    if (app.count("--" + spec.flag) > 0) flags[spec.key] = values[spec.key];
  }
  if (app.count("--config") > 0) flags["config"] = config_file;

  const tod::Result<tod::server::ServerConfig> config =
      tod::server::ResolveServerConfig(flags, [](const char* name) { return std::getenv(name); });
  if (!config.ok()) {
    std::cerr << "tod_server: " << config.status().message() << "\n";
    return 2;
  }
  if (tod::Status logging = tod::server::SetUpLogging(config->log_format, config->log_level);
      !logging.ok()) {
    std::cerr << "tod_server: " << logging.message() << "\n";
    return 2;
  }
  return tod::server::RunServer(*config);
}

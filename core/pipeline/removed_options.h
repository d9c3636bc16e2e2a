// Options of `tod train` that were measured, not adopted, and removed together with their code
// (docs/findings.md, "Real frames, not adopted"). Their manifest keys outlive them: new bundles
// still record each at the one value that remains, so a manifest reads as those written before
// the removal, and a bundle that records another value was trained with code this build no
// longer has. Such a bundle is refused at load, naming the option and how to retrain; silently
// running it without what it was trained with would give other scores than it was measured at.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/base/status.h"

namespace tod {

struct RemovedOption {
  std::string flag;      // as `tod train` spelled it
  std::string key;       // JSON pointer into manifest.json
  nlohmann::json value;  // the one value it may hold now
  std::string finding;   // anchor in docs/findings.md
};

// Every removed option's keys, /params ones first.
const std::vector<RemovedOption>& RemovedOptions();

// Writes the /params keys of RemovedOptions() at their value into `params` (the manifest's
// "params" object).
void WriteRemovedParams(nlohmann::json& params);

// FailedPrecondition naming the first removed option `manifest` records at another value, with
// the command that retrains the bundle (from its own training record); Ok when there is none.
// Keys the manifest lacks are fine: those bundles predate the option. `where`: the manifest's
// path, for the message.
Status RefuseRemovedOptions(const nlohmann::json& manifest, const std::string& where);

}  // namespace tod

// The model paths of the Open Inference Protocol, parsed in one place because the router matches
// only fixed paths (and a prefix): /v2/models/{name}[/versions/{version}][/ready | /infer].
#pragma once

#include <optional>
#include <string>
#include <string_view>

namespace tod::server::oip {

inline constexpr std::string_view kModelsPrefix = "/v2/models/";

enum class ModelAction { kMetadata, kReady, kInfer };

struct ModelPath {
  std::string name;
  std::optional<std::string> version;
  ModelAction action = ModelAction::kMetadata;
};

// `path` (no query string) split into its parts, each percent-decoded; nullopt when it is not one
// of the protocol's model paths (an empty segment, a bad %-escape, an unknown last part).
std::optional<ModelPath> ParseModelPath(std::string_view path);

}  // namespace tod::server::oip

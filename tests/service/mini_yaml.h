// A small parser for the block-style YAML subset that Kubernetes manifests and `kubectl kustomize`
// output use (mappings, sequences incl. "- key: v" items at the parent's indent, plain and quoted
// scalars, one-line flow sequences of scalars, block scalars kept as text). Enough to check the
// manifests' structure in tests without a YAML library.
#pragma once

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "core/base/status.h"

namespace tod::server::testing {

struct YamlNode {
  enum class Kind { kNull, kScalar, kMap, kSeq };
  Kind kind = Kind::kNull;
  std::string scalar;
  std::vector<std::pair<std::string, YamlNode>> entries;  // kMap, in file order
  std::vector<YamlNode> items;                            // kSeq

  // Child by key (kMap) or nullptr.
  const YamlNode* Get(const std::string& key) const;
  // Walks "a.b.c" through maps; nullptr when any step is missing.
  const YamlNode* Path(const std::string& dotted) const;
  std::string Str(const std::string& dotted, const std::string& fallback = "") const;
};

// Parses a stream of documents separated by "---".
Result<std::vector<YamlNode>> ParseYamlDocuments(const std::string& text);

}  // namespace tod::server::testing

#include "core/pipeline/model_bundle.h"

#include <unistd.h>

#include <chrono>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>

#include "core/base/atomic_file.h"
#include "core/base/binary_io.h"
#include "core/base/checksum.h"
#include "core/features/box_features.h"
#include "core/pipeline/json_integers.h"
#include "core/pipeline/removed_options.h"

namespace tod {
namespace fs = std::filesystem;
namespace {

constexpr const char* kManifest = "manifest.json";
constexpr const char* kEdgesFile = "edges.bin";
constexpr const char* kOcclusionFile = "occlusion.bin";
constexpr const char* kOrdrFile = "ordr.bin";
constexpr const char* kObdrFile = "obdr.bin";
constexpr const char* kSedModelFile = "sed_model.yml.gz";

// The manifest's checksum of a file ("fnv1a64"), as hex. Its basis is a digit short of FNV's
// standard offset basis (14695981039346656037): every manifest written so far carries checksums
// made with it, so it stays, as part of the bundle format.
constexpr std::uint64_t kManifestChecksumBasis = 1469598103934665603ULL;
std::string ChecksumHex(const std::string& bytes) {
  std::ostringstream s;
  s << std::hex << Fnv1a64(bytes, kManifestChecksumBasis);
  return s.str();
}

Result<std::string> ReadFile(const fs::path& path) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) return Status::NotFound(path.string() + ": missing");
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::NotFound(path.string() + ": cannot open");
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace

std::string NowIso8601() {
  const std::time_t t = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

Status SaveModelBundle(const ModelBundle& bundle, const std::string& dir,
                       const std::string& sed_model_source) {
  const fs::path target = fs::absolute(dir);
  std::error_code ec;
  fs::create_directories(target.parent_path(), ec);
  // Appended rather than built from a literal: GCC 12 warns falsely (-Wrestrict) on
  // "literal" + std::string.
  std::string suffix(".");
  suffix.append(std::to_string(::getpid())).append(".tmp");
  const fs::path tmp = target.parent_path() / (target.filename().string() + suffix);
  fs::remove_all(tmp, ec);
  if (!fs::create_directories(tmp, ec))
    return Status::Internal("cannot create " + tmp.string() + ": " + ec.message());

  nlohmann::json files = nlohmann::json::object();
  auto add = [&](const char* name, const Result<std::string>& bytes) -> Status {
    if (!bytes.ok()) return bytes.status();
    Status st = WriteFileAtomically((tmp / name).string(), *bytes);
    if (!st.ok()) return st;
    files[name] = {{"bytes", bytes->size()}, {"fnv1a64", ChecksumHex(*bytes)}};
    return Status::Ok();
  };
  Status st;
  switch (bundle.edge_kind) {
    case EdgeKind::kPixelForest: {
      const auto* classifier = dynamic_cast<const PixelEdgeClassifier*>(bundle.edges.get());
      if (classifier == nullptr)
        return Status::InvalidArgument("pixel_forest bundle without classifier");
      st = add(kEdgesFile, EncodeModel(*classifier));
      break;
    }
    case EdgeKind::kSed:
      st = add(kSedModelFile, ReadFile(sed_model_source));
      break;
    case EdgeKind::kGradient:
      break;  // nothing learned
  }
  if (!st.ok()) return st;
  if ((st = add(kOcclusionFile, EncodeModel(bundle.occlusion))); !st.ok()) return st;
  if ((st = add(kOrdrFile, EncodeModel(bundle.ordr))); !st.ok()) return st;
  if ((st = add(kObdrFile, EncodeModel(bundle.obdr))); !st.ok()) return st;

  nlohmann::json manifest;
  manifest["format_version"] = kBundleFormatVersion;
  manifest["version"] = bundle.version;
  manifest["created"] = bundle.created.empty() ? NowIso8601() : bundle.created;
  manifest["edge_source"] = EnumString(bundle.edge_kind);
  if (bundle.edge_kind == EdgeKind::kSed) manifest["sed_model_file"] = kSedModelFile;
  manifest["params"] = ToJson(bundle.params);
  manifest["regions"] = bundle.regions.ToJson();
  manifest["size_filter"] = bundle.size_filter.ToJson();
  if (bundle.horizon_reference) manifest["horizon_reference"] = bundle.horizon_reference->ToJson();
  manifest["training"] = bundle.training;
  manifest["eval"] = bundle.eval;
  manifest["files"] = files;
  if ((st = WriteFileAtomically((tmp / kManifest).string(), manifest.dump(2) + "\n")); !st.ok())
    return st;

  // Swap in: move an existing bundle aside, rename the new one, then delete the old one.
  const fs::path old = target.parent_path() /
                       (target.filename().string() + "." + std::to_string(::getpid()) + ".old");
  const bool had_old = fs::exists(target, ec);
  if (had_old) {
    fs::remove_all(old, ec);
    fs::rename(target, old, ec);
    if (ec) return Status::Internal("cannot move old bundle aside: " + ec.message());
  }
  fs::rename(tmp, target, ec);
  if (ec) {
    if (had_old) fs::rename(old, target, ec);
    return Status::Internal("cannot rename " + tmp.string() + " to " + target.string());
  }
  if (had_old) fs::remove_all(old, ec);
  return Status::Ok();
}

namespace {

// The bundle directory's manifest and what it says about the learned files, which are read
// only through it: present, of the recorded size and checksum.
struct BundleFiles {
  fs::path root;
  std::string manifest_path;
  nlohmann::json manifest;

  Result<std::string> Checked(const std::string& name) const {
    const fs::path path = root / name;
    auto bytes = ReadFile(path);
    if (!bytes.ok()) return bytes.status();
    if (!manifest.contains("files") || !manifest["files"].contains(name))
      return Status::DataLoss(manifest_path + ": no entry for " + name);
    const auto& entry = manifest["files"][name];
    const std::size_t expected = entry.value("bytes", std::size_t{0});
    if (bytes->size() != expected)
      return Status::DataLoss(path.string() + ": truncated or altered (" +
                              std::to_string(bytes->size()) + " bytes, manifest says " +
                              std::to_string(expected) + ")");
    if (ChecksumHex(*bytes) != entry.value("fnv1a64", ""))
      return Status::DataLoss(path.string() + ": checksum mismatch (file corrupted)");
    return bytes;
  }

  // A checked file parsed as a model of type T.
  template <typename T>
  Result<T> Decoded(const std::string& name) const {
    auto bytes = Checked(name);
    if (!bytes.ok()) return bytes.status();
    return DecodeModel<T>(*bytes, (root / name).string());
  }
};

Result<BundleFiles> OpenBundle(const std::string& dir) {
  BundleFiles files;
  files.root = fs::path(dir);
  std::error_code ec;
  if (!fs::is_directory(files.root, ec))
    return Status::NotFound(dir + ": model bundle directory does not exist");
  auto manifest_text = ReadFile(files.root / kManifest);
  if (!manifest_text.ok()) return manifest_text.status();
  files.manifest_path = (files.root / kManifest).string();
  try {
    files.manifest = nlohmann::json::parse(*manifest_text);
  } catch (const nlohmann::json::exception& e) {
    return Status::DataLoss(files.manifest_path + ": not valid JSON (" + e.what() + ")");
  }
  return files;
}

// The manifest's own fields: format version, parameters, regions, size filter, records.
Status ReadManifestFields(const BundleFiles& files, ModelBundle& bundle) {
  const nlohmann::json& manifest = files.manifest;
  const std::string& where = files.manifest_path;
  try {
    const Result<int> version = JsonToInt(manifest.at("format_version"), "format_version");
    if (!version.ok()) return Status::InvalidArgument(where + ": " + version.status().message());
    if (*version != kBundleFormatVersion)
      return Status::FailedPrecondition(where + ": format_version " + std::to_string(*version) +
                                        ", this build reads " +
                                        std::to_string(kBundleFormatVersion));
    if (Status st = RefuseRemovedOptions(manifest, where); !st.ok()) return st;
    bundle.version = manifest.value("version", "");
    bundle.created = manifest.value("created", "");
    const std::string edge_source = manifest.at("edge_source").get<std::string>();
    const std::optional<EdgeKind> edge_kind = ParseEnum<EdgeKind>(edge_source);
    if (!edge_kind)
      return Status::InvalidArgument(where + ": unknown edge_source '" + edge_source + "' (" +
                                     EnumNamesInWords<EdgeKind>() + ")");
    bundle.edge_kind = *edge_kind;
    auto params = PipelineParamsFromJson(manifest.at("params"));
    if (!params.ok()) return Status::InvalidArgument(where + ": " + params.status().message());
    bundle.params = *params;
    auto regions = MultilayerRegions::FromJson(manifest.at("regions"));
    if (!regions.ok()) return Status::InvalidArgument(where + ": " + regions.status().message());
    bundle.regions = *regions;
    bundle.size_filter = SizeFilter::FromJson(manifest.at("size_filter"));
    if (manifest.contains("horizon_reference")) {
      auto reference = HorizonReference::FromJson(manifest["horizon_reference"]);
      if (!reference.ok())
        return Status::InvalidArgument(where + ": " + reference.status().message());
      bundle.horizon_reference = *reference;
    }
    bundle.training = manifest.value("training", nlohmann::json());
    bundle.eval = manifest.value("eval", nlohmann::json());
  } catch (const nlohmann::json::exception& e) {
    return Status::InvalidArgument(where + ": " + e.what());
  }
  return Status::Ok();
}

// ORDR and OBDR. The manifest's feature set decides the row width; a forest of the other width
// was trained on other features, and reading its rows shifted would be silently wrong.
Status LoadRegressors(const BundleFiles& files, ModelBundle& bundle) {
  auto ordr = files.Decoded<RandomForest>(kOrdrFile);
  if (!ordr.ok()) return ordr.status();
  auto obdr = files.Decoded<RandomForest>(kObdrFile);
  if (!obdr.ok()) return obdr.status();
  bundle.ordr = std::move(*ordr);
  bundle.obdr = std::move(*obdr);
  const int features = ProposalFeatureCount(bundle.params);
  if (bundle.ordr.num_features() == features && bundle.obdr.num_features() == features)
    return Status::Ok();
  return Status::DataLoss((files.root / kOrdrFile).string() + ": regressors must take " +
                          std::to_string(features) + " features (" +
                          ProposalFeatureSet(bundle.params) + "), not " +
                          std::to_string(bundle.ordr.num_features()) + " / " +
                          std::to_string(bundle.obdr.num_features()));
}

// No silent fallback: an untrained classifier would paint mean-Ê boundaries instead of the
// learned occlusion edges. Only a manifest that switches the part off on purpose loads one.
Status LoadOcclusionClassifier(const BundleFiles& files, ModelBundle& bundle) {
  auto loaded = files.Decoded<OcclusionClassifier>(kOcclusionFile);
  if (!loaded.ok()) return loaded.status();
  bundle.occlusion = std::move(*loaded);
  const nlohmann::json parts = bundle.training.is_object()
                                   ? bundle.training.value("parts", nlohmann::json::object())
                                   : nlohmann::json::object();
  const bool deliberately_off =
      parts.contains("occlusion") && parts["occlusion"].value("off", false);
  if (bundle.occlusion.trained() || deliberately_off) return Status::Ok();
  return Status::FailedPrecondition(
      (files.root / kOcclusionFile).string() +
      ": the occlusion classifier is untrained and the manifest does not switch it off "
      "(training.parts.occlusion.off)");
}

// The base edge source the manifest names: the trained pixel forest, the gradient, or SED.
Status LoadBaseEdgeSource(const BundleFiles& files, ModelBundle& bundle) {
  switch (bundle.edge_kind) {
    case EdgeKind::kPixelForest: {
      auto loaded = files.Decoded<PixelEdgeClassifier>(kEdgesFile);
      if (!loaded.ok()) return loaded.status();
      bundle.edges = std::make_shared<PixelEdgeClassifier>(std::move(*loaded));
      return Status::Ok();
    }
    case EdgeKind::kGradient:
      bundle.edges = CreateGradientEdgeSource(bundle.params.gradient_edges);
      return Status::Ok();
    case EdgeKind::kSed: {
      bundle.sed_model_file = files.manifest.value("sed_model_file", kSedModelFile);
      auto bytes = files.Checked(bundle.sed_model_file);
      if (!bytes.ok()) return bytes.status();
      auto sed = CreateSedEdgeSource((files.root / bundle.sed_model_file).string());
      if (!sed.ok()) return sed.status();
      bundle.edges = std::shared_ptr<const EdgeSource>(std::move(*sed));
      return Status::Ok();
    }
  }
  return Status::Internal("unhandled edge kind");
}

}  // namespace

Result<ModelBundle> LoadModelBundle(const std::string& dir) {
  auto files = OpenBundle(dir);
  if (!files.ok()) return files.status();
  ModelBundle bundle;
  for (const auto step :
       {ReadManifestFields, LoadRegressors, LoadOcclusionClassifier, LoadBaseEdgeSource}) {
    if (Status st = step(*files, bundle); !st.ok()) return st;
  }
  return bundle;
}

Status UpdateManifestField(const std::string& dir, const std::string& field,
                           const nlohmann::json& value) {
  const fs::path path = fs::path(dir) / kManifest;
  auto text = ReadFile(path);
  if (!text.ok()) return text.status();
  nlohmann::json manifest;
  try {
    manifest = nlohmann::json::parse(*text);
  } catch (const nlohmann::json::exception& e) {
    return Status::DataLoss(path.string() + ": not valid JSON");
  }
  manifest[field] = value;
  return WriteFileAtomically(path.string(), manifest.dump(2) + "\n");
}

}  // namespace tod

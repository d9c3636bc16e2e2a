// One entry point for the model bundle to build whichever edge source it was trained with.
#include <memory>
#include <string>

#include "core/edges/edge_source.h"

namespace tod {

Result<std::unique_ptr<EdgeSource>> LoadEdgeSource(const std::string& kind, BinaryReader* in,
                                                   const std::string& what) {
  if (kind == "gradient") return CreateGradientEdgeSource();
  if (kind == "sed") return CreateSedEdgeSource(what);
  if (kind == "pixel_forest") {
    if (in == nullptr) {
      return Status::InvalidArgument("edge source 'pixel_forest' from '" + what + "': no input");
    }
    Result<PixelEdgeClassifier> classifier = PixelEdgeClassifier::Load(*in);
    if (!classifier.ok()) return classifier.status();
    return std::unique_ptr<EdgeSource>(
        std::make_unique<PixelEdgeClassifier>(std::move(classifier).value()));
  }
  return Status::InvalidArgument("unknown edge source kind '" + kind + "' in '" + what +
                                 "' (expected gradient, pixel_forest or sed)");
}

}  // namespace tod

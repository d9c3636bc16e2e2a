// Writes the seed corpora of the fuzz targets, each file made with the project's own writers (or,
// for images and MAT files, OpenCV's and libmatio's) so that the seeds are valid inputs the
// fuzzer then mutates: usage `fuzz_seed_gen OUT_DIR`, writing OUT_DIR/<target>/<seed>.
// tests/fuzz/run_fuzzers.sh --seeds runs it into tests/fuzz/corpus/. Deterministic: fixed seeds,
// fixed MAT header text, so regenerating gives the same files.
#include <matio.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "core/edges/edge_source.h"
#include "core/edges/occlusion_classifier.h"
#include "core/edges/occlusion_features.h"
#include "core/forest/random_forest.h"
#include "core/pipeline/multilayer_regions.h"
#include "core/pipeline/pipeline_params.h"
#include "core/proposals/size_filter.h"
#include "inference/grpc_service.pb.h"
#include "tod/v1/obstacle_discovery.pb.h"

namespace {

namespace fs = std::filesystem;

fs::path out_root;

void Write(const std::string& target, const std::string& name, const std::string& bytes) {
  const fs::path dir = out_root / target;
  fs::create_directories(dir);
  std::ofstream out(dir / name, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!out) {
    std::cerr << "fuzz_seed_gen: cannot write " << (dir / name) << "\n";
    std::exit(1);
  }
}

std::string Encode(const std::string& ext, const cv::Mat& image, const std::vector<int>& params) {
  std::vector<uchar> bytes;
  if (!cv::imencode(ext, image, bytes, params)) {
    std::cerr << "fuzz_seed_gen: cannot encode " << ext << "\n";
    std::exit(1);
  }
  return std::string(bytes.begin(), bytes.end());
}

// A small frame with something to find: grey road, a dark block.
cv::Mat3b TinyFrame(int width, int height) {
  cv::Mat3b frame(height, width, cv::Vec3b(110, 112, 115));
  cv::rectangle(frame, cv::Rect(width / 3, height / 2, width / 4, height / 4),
                cv::Scalar(30, 40, 50), cv::FILLED);
  return frame;
}

template <typename Model>
std::string Saved(const Model& model) {
  tod::Result<std::string> bytes = tod::EncodeModel(model);
  if (!bytes.ok()) {
    std::cerr << "fuzz_seed_gen: cannot save a model: " << bytes.status().message() << "\n";
    std::exit(1);
  }
  return std::move(bytes).value();
}

tod::RandomForest TinyForest(int num_features, int trees, std::uint64_t seed) {
  cv::RNG rng(seed);
  cv::Mat1f features(40, num_features);
  rng.fill(features, cv::RNG::UNIFORM, 0.f, 1.f);
  std::vector<float> targets;
  for (int r = 0; r < features.rows; ++r) targets.push_back(features(r, 0) > 0.5f ? 1.f : 0.f);
  tod::ForestParams params;
  params.num_trees = trees;
  params.max_depth = 3;
  params.min_leaf_size = 4;
  params.seed = seed;
  params.threads = 1;
  tod::Result<tod::RandomForest> forest = tod::RandomForest::Fit(features, targets, params);
  if (!forest.ok()) {
    std::cerr << "fuzz_seed_gen: " << forest.status().message() << "\n";
    std::exit(1);
  }
  return std::move(forest).value();
}

void ImageSeeds() {
  const cv::Mat3b frame = TinyFrame(12, 8);
  cv::Mat1b grey;
  cv::cvtColor(frame, grey, cv::COLOR_BGR2GRAY);
  cv::Mat1w deep;
  grey.convertTo(deep, CV_16U, 256);
  Write("fuzz_image_decode", "rgb.png", Encode(".png", frame, {}));
  Write("fuzz_image_decode", "grey.png", Encode(".png", grey, {}));
  Write("fuzz_image_decode", "grey16.png", Encode(".png", deep, {}));
  Write("fuzz_image_decode", "baseline.jpg", Encode(".jpg", frame, {cv::IMWRITE_JPEG_QUALITY, 80}));
  Write("fuzz_image_decode", "grey.jpg", Encode(".jpg", grey, {cv::IMWRITE_JPEG_QUALITY, 80}));
  Write("fuzz_image_decode", "progressive.jpg",
        Encode(".jpg", frame, {cv::IMWRITE_JPEG_PROGRESSIVE, 1, cv::IMWRITE_JPEG_QUALITY, 70}));
  cv::Mat alpha;
  cv::cvtColor(frame, alpha, cv::COLOR_BGR2BGRA);
  for (const std::string target : {"fuzz_image_decode", "fuzz_webp_decode"}) {
    Write(target, "lossy.webp", Encode(".webp", frame, {cv::IMWRITE_WEBP_QUALITY, 60}));
    Write(target, "lossless.webp", Encode(".webp", frame, {cv::IMWRITE_WEBP_QUALITY, 101}));
    Write(target, "alpha.webp", Encode(".webp", alpha, {cv::IMWRITE_WEBP_QUALITY, 101}));
  }
}

void RestSeeds() {
  const std::string png = Encode(".png", TinyFrame(4, 4), {});
  auto post = [&](const std::string& target, const std::string& type) {
    return "POST " + target + " HTTP/1.1\r\nHost: tod\r\nContent-Type: " + type +
           "\r\nContent-Length: " + std::to_string(png.size()) + "\r\n\r\n" + png;
  };
  Write("fuzz_rest_request", "detect",
        post("/v1/detect?max_proposals=20&obstacle_threshold=0.5&map=none", "image/png"));
  Write("fuzz_rest_request", "detect_all_options",
        post("/v1/detect?max_proposals=10000&obstacle_threshold=1e-3&map=png&timeout_ms=3600000"
             "&frame_id=cam%2F0+frame%201",
             "image/png; charset=binary"));
  Write("fuzz_rest_request", "probability_map",
        post("/v1/probability-map?timeout_ms=250&frame_id=f", "image/jpeg"));
  Write("fuzz_rest_request", "chunked",
        "POST /v1/detect?map=none HTTP/1.1\r\nHost: tod\r\nContent-Type: image/png\r\n"
        "Transfer-Encoding: chunked\r\n\r\n4\r\nabcd\r\n0\r\n\r\n");
  Write("fuzz_rest_request", "model", "GET /v1/model HTTP/1.1\r\nHost: tod\r\n\r\n");
  Write("fuzz_rest_request", "ready", "GET /v2/health/ready HTTP/1.0\r\n\r\n");
  Write("fuzz_rest_request", "wrong_method",
        "PUT /v1/detect HTTP/1.1\r\nContent-Length: 0\r\n\r\n");
}

// One BYTES element in its binary form: a 4-byte little-endian length, then the bytes.
std::string BytesElement(const std::string& bytes) {
  std::string element;
  for (int shift = 0; shift < 32; shift += 8) {
    element.push_back(static_cast<char>(bytes.size() >> shift));
  }
  return element + bytes;
}

// The first byte picks the parser (fuzz_oip_request.cc): 0 JSON, 1 JSON + binary, 2 gRPC.
void OipSeeds() {
  const std::string png = Encode(".png", TinyFrame(4, 4), {});
  const std::string json =
      R"({"id":"f1","parameters":{"max_proposals":20,"map_format":"uint8"},)"
      R"("inputs":[{"name":"image","datatype":"BYTES","shape":[1],"data":["iVBORw0KGgo="]}],)"
      R"("outputs":[{"name":"obstacles"},{"name":"probability_map","parameters":{"binary_data":true}}]})";
  Write("fuzz_oip_request", "json", std::string(1, '\0') + json);
  const std::string header =
      R"({"inputs":[{"name":"image","datatype":"BYTES","shape":[1],)"
      R"("parameters":{"binary_data_size":)" +
      std::to_string(png.size() + 4) + "}}]}";
  const std::string length = {static_cast<char>(header.size() & 0xff),
                              static_cast<char>(header.size() >> 8)};
  Write("fuzz_oip_request", "binary", std::string(1, '\1') + length + header + BytesElement(png));

  inference::ModelInferRequest request;
  request.set_model_name("default");
  request.set_id("f2");
  (*request.mutable_parameters())["max_proposals"].set_int64_param(5);
  (*request.mutable_parameters())["map_format"].set_string_param("png");
  auto* input = request.add_inputs();
  input->set_name("image");
  input->set_datatype("BYTES");
  input->add_shape(1);
  request.add_raw_input_contents(BytesElement(png));
  request.add_outputs()->set_name("proposals");
  Write("fuzz_oip_request", "grpc_raw", std::string(1, '\2') + request.SerializeAsString());
  request.clear_raw_input_contents();
  input->mutable_contents()->add_bytes_contents(png);
  Write("fuzz_oip_request", "grpc_contents", std::string(1, '\2') + request.SerializeAsString());
}

void GrpcSeeds() {
  tod::v1::DetectRequest request;
  request.set_image(Encode(".png", TinyFrame(6, 4), {}));
  Write("fuzz_grpc_request", "image_only", request.SerializeAsString());
  request.set_frame_id("camera-0/000001");
  request.mutable_options()->set_max_proposals(20);
  request.mutable_options()->set_obstacle_threshold(0.5f);
  request.mutable_options()->set_map_format(tod::v1::MAP_FORMAT_NONE);
  Write("fuzz_grpc_request", "all_fields", request.SerializeAsString());
  request.set_image(Encode(".jpg", TinyFrame(6, 4), {cv::IMWRITE_JPEG_QUALITY, 60}));
  request.mutable_options()->set_max_proposals(10001);  // out of range: refused
  Write("fuzz_grpc_request", "jpeg_bad_option", request.SerializeAsString());
  Write("fuzz_grpc_request", "empty", "");
}

void ModelSeeds() {
  Write("fuzz_model_files", "forest.bin", Saved(TinyForest(20, 2, 1)));
  Write("fuzz_model_files", "empty_forest.bin", Saved(tod::RandomForest()));
  // occlusion.bin of an untrained classifier, and a trained one: the same header with the trained
  // flag (its last byte) set, followed by a forest over the 17 pair features (Save's layout).
  const std::string untrained = Saved(tod::OcclusionClassifier());
  Write("fuzz_model_files", "occlusion_untrained.bin", untrained);
  std::string trained = untrained;
  trained.back() = 1;
  trained += Saved(TinyForest(tod::kNumOcclusionFeatures, 2, 2));
  Write("fuzz_model_files", "occlusion_trained.bin", trained);
  // edges.bin: a pixel edge classifier trained on one small frame whose labels outline a block.
  tod::EdgeTrainingFrame frame;
  frame.image = TinyFrame(40, 32);
  frame.labels = cv::Mat1i(32, 40, 1);
  frame.labels(cv::Rect(40 / 3, 16, 10, 8)).setTo(2);
  tod::PixelEdgeParams params;
  params.samples_per_frame = 60;
  params.forest.num_trees = 2;
  params.forest.max_depth = 4;
  params.forest.threads = 1;
  tod::Result<tod::PixelEdgeClassifier> edges = tod::PixelEdgeClassifier::TryTrain({frame}, params);
  if (!edges.ok()) {
    std::cerr << "fuzz_seed_gen: " << edges.status().message() << "\n";
    std::exit(1);
  }
  Write("fuzz_model_files", "edges.bin", Saved(*edges));
}

void ManifestSeeds() {
  nlohmann::json manifest;
  manifest["format_version"] = 1;
  manifest["edge_source"] = "pixel_forest";
  manifest["params"] = tod::ToJson(tod::PipelineParams());
  manifest["regions"] = tod::Laf2020Regions().ToJson();
  manifest["size_filter"] = tod::SizeFilter::Laf2020().ToJson();
  Write("fuzz_manifest", "laf2020.json", manifest.dump(1) + "\n");
  nlohmann::json small;
  small["params"] = {{"regions", {{"num_layers", 2}}}, {"boxes", {{"refine_limit", 10}}}};
  small["regions"] = {
      {"image_width", 64}, {"image_height", 32}, {"layers", {{0, 8, 64, 24}, {16, 12, 32, 12}}}};
  small["size_filter"] = {{"enabled", false}, {"bands", nlohmann::json::array()}};
  Write("fuzz_manifest", "small.json", small.dump() + "\n");
}

// Raw mask seeds in fuzz_mask_reader's format (see there), and one PNG mask.
void MaskSeeds() {
  std::string raw = {0, 0, 15, 11, 0};  // raw, 8-bit, 16 x 12, no flags
  for (int y = 0; y < 12; ++y) {
    for (int x = 0; x < 16; ++x) {
      const bool obstacle = x >= 5 && x < 10 && y >= 4 && y < 9;
      const bool speck = x == 13 && y == 2;
      const bool in_void = y == 11;
      raw.push_back(static_cast<char>(in_void ? 2 : obstacle || speck ? 1 : 0));
    }
  }
  Write("fuzz_mask_reader", "raw_16x12", raw);
  cv::Mat1b mask(12, 16, uchar{0});
  mask(cv::Rect(5, 4, 5, 5)).setTo(1);
  mask.row(11).setTo(255);
  Write("fuzz_mask_reader", "mask.png", std::string(1, '\1') + Encode(".png", mask, {}));
}

// LAF seeds in fuzz_laf_reader's format: 16 x 12, 16-bit instanceIds, 8-bit labelIds.
void LafSeeds() {
  std::string raw = {15, 11, 0, 0, 0};
  for (int y = 0; y < 12; ++y) {
    for (int x = 0; x < 16; ++x) {
      int b = y < 4 ? 0 : 1;                                     // ignore above, road below
      if (x >= 3 && x < 7 && y >= 5 && y < 9) b = 2 + 4 * 1;     // obstacle instance 1002
      if (x >= 10 && x < 13 && y >= 6 && y < 10) b = 2 + 4 * 3;  // obstacle instance 1004
      raw.push_back(static_cast<char>(b));
    }
  }
  Write("fuzz_laf_reader", "two_obstacles", raw);
}

// An annotation MAT file (struct 'annotations' with sea_edge Nx2 and obstacles Mx4), written with
// a fixed header text so that the bytes do not depend on the date.
void WriteAnnotationMat(const std::string& name, const std::vector<double>& sea_edge_xy,
                        const std::vector<double>& boxes_xywh, matio_compression compression,
                        matio_classes class_type) {
  const fs::path dir = out_root / "fuzz_modd2_mat";
  fs::create_directories(dir);
  const std::string path = (dir / name).string();
  fs::remove(path);
  mat_t* mat =
      Mat_CreateVer(path.c_str(), "MATLAB 5.0 MAT-file, written by tod fuzz_seed_gen", MAT_FT_MAT5);
  const char* fields[] = {"sea_edge", "obstacles"};
  std::size_t one[2] = {1, 1};
  matvar_t* annotations = Mat_VarCreateStruct("annotations", 2, one, fields, 2);
  auto field = [&](const std::vector<double>& row_major, std::size_t cols) {
    const std::size_t rows = row_major.size() / cols;
    std::vector<double> doubles(row_major.size());
    std::vector<float> floats(row_major.size());
    for (std::size_t r = 0; r < rows; ++r) {
      for (std::size_t c = 0; c < cols; ++c) {
        doubles[r + c * rows] = row_major[r * cols + c];
        floats[r + c * rows] = static_cast<float>(row_major[r * cols + c]);
      }
    }
    std::size_t dims[2] = {rows, cols};
    const bool single = class_type == MAT_C_SINGLE;
    return Mat_VarCreate(nullptr, class_type, single ? MAT_T_SINGLE : MAT_T_DOUBLE, 2, dims,
                         single ? static_cast<void*>(floats.data()) : doubles.data(), 0);
  };
  Mat_VarSetStructFieldByName(annotations, "sea_edge", 0, field(sea_edge_xy, 2));
  Mat_VarSetStructFieldByName(annotations, "obstacles", 0, field(boxes_xywh, 4));
  const bool ok = mat != nullptr && Mat_VarWrite(mat, annotations, compression) == 0;
  Mat_VarFree(annotations);
  if (mat != nullptr) Mat_Close(mat);
  if (!ok) {
    std::cerr << "fuzz_seed_gen: cannot write " << path << "\n";
    std::exit(1);
  }
}

void Modd2Seeds() {
  // Coordinates for the 64 x 48 frame the fuzzer uses (1-based, as MODDv2 stores them).
  const std::vector<double> sea_edge = {1, 20, 20, 18, 40, 21, 64, 19};
  const std::vector<double> boxes = {10, 30, 8, 6, 30, 10, 20, 15, 50, 40, 3, 2};
  WriteAnnotationMat("plain.mat", sea_edge, boxes, MAT_COMPRESSION_NONE, MAT_C_DOUBLE);
  WriteAnnotationMat("single.mat", sea_edge, boxes, MAT_COMPRESSION_NONE, MAT_C_SINGLE);
  WriteAnnotationMat("compressed.mat", sea_edge, boxes, MAT_COMPRESSION_ZLIB, MAT_C_DOUBLE);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  WriteAnnotationMat("nan_edge_no_boxes.mat", {1, 20, nan, nan, 64, 22}, {}, MAT_COMPRESSION_NONE,
                     MAT_C_DOUBLE);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: fuzz_seed_gen OUT_DIR\n";
    return 2;
  }
  out_root = argv[1];
  cv::setRNGSeed(1);
  ImageSeeds();
  RestSeeds();
  GrpcSeeds();
  OipSeeds();
  ModelSeeds();
  ManifestSeeds();
  MaskSeeds();
  LafSeeds();
  Modd2Seeds();
  std::cout << "fuzz_seed_gen: seeds written under " << out_root << "\n";
  return 0;
}

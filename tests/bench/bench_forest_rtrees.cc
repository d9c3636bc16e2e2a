// Our RandomForest vs OpenCV cv::ml::RTrees on the same synthetic regression problem, both set up
// as ALGORITHM.md §6.3 asks (200 trees, mtry 6, min leaf / min sample count 5, deep trees).
// Prints medians over repeats: train time, predict time per 1000 rows, serialised size, load
// time, held-out MSE. Usage: bench_forest_rtrees [repeats=3] [train_rows=20000]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <opencv2/ml.hpp>
#include <random>
#include <string>
#include <vector>

#include "core/base/atomic_file.h"
#include "core/forest/random_forest.h"

namespace {

constexpr int kFeatures = 20;
constexpr int kTestRows = 5000;

struct Data {
  cv::Mat1f x;
  std::vector<float> y;
};

// A smooth non-linear target over 5 of the 20 features plus noise; the rest are distractors.
Data MakeData(int rows, unsigned seed) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<float> uniform(0.f, 1.f);
  std::normal_distribution<float> noise(0.f, 0.1f);
  Data d{cv::Mat1f(rows, kFeatures), std::vector<float>(rows)};
  for (int r = 0; r < rows; ++r) {
    float* x = d.x[r];
    for (int c = 0; c < kFeatures; ++c) x[c] = uniform(gen);
    d.y[r] =
        std::sin(6.f * x[0]) + 2.f * x[1] * x[2] + (x[3] > 0.5f ? 1.f : 0.f) - x[4] + noise(gen);
  }
  return d;
}

double Seconds(const std::function<void()>& work) {
  const auto start = std::chrono::steady_clock::now();
  work();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

double Mse(const std::vector<float>& predicted, const std::vector<float>& truth) {
  double sum = 0.0;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    const double e = predicted[i] - truth[i];
    sum += e * e;
  }
  return sum / static_cast<double>(truth.size());
}

struct Row {
  std::vector<double> train_s, predict_ms_per_1000, load_ms, mse;
  double bytes = 0, bytes_gz = 0;
};

void Ours(const Data& train, const Data& test, int threads, Row& row) {
  tod::ForestParams params;  // defaults: 200 trees, mtry 6, min leaf 5, unlimited depth
  params.threads = threads;
  tod::RandomForest forest;
  row.train_s.push_back(Seconds(
      [&] { forest = std::move(tod::RandomForest::Fit(train.x, train.y, params)).value(); }));
  std::vector<float> predicted;
  const double predict_s = Seconds([&] { predicted = forest.PredictBatch(test.x); });
  row.predict_ms_per_1000.push_back(1000.0 * predict_s * 1000.0 / test.x.rows);
  row.mse.push_back(Mse(predicted, test.y));
  const std::string bytes = tod::EncodeModel(forest).value();  // a forest's Save cannot fail
  row.bytes = static_cast<double>(bytes.size());
  const std::string path = (std::filesystem::temp_directory_path() / "bench_forest.bin").string();
  if (!tod::WriteFileAtomically(path, bytes).ok())
    std::fprintf(stderr, "cannot write %s\n", path.c_str());
  row.load_ms.push_back(1000.0 * Seconds([&] {
                          std::ifstream in(path, std::ios::binary);
                          const std::string file((std::istreambuf_iterator<char>(in)), {});
                          const auto loaded = tod::DecodeModel<tod::RandomForest>(file, path);
                          if (!loaded.ok())
                            std::fprintf(stderr, "%s\n", loaded.status().message().c_str());
                        }));
  std::filesystem::remove(path);
}

void OpenCvRTrees(const Data& train, const Data& test, Row& row) {
  cv::Ptr<cv::ml::RTrees> trees = cv::ml::RTrees::create();
  trees->setMaxDepth(30);
  trees->setMinSampleCount(5);
  trees->setActiveVarCount(6);
  trees->setRegressionAccuracy(0.f);
  trees->setUseSurrogates(false);
  trees->setCalculateVarImportance(false);
  trees->setTermCriteria(cv::TermCriteria(cv::TermCriteria::MAX_ITER, 200, 0.0));
  cv::Mat1f responses(train.y, true);
  cv::Mat var_type(1, kFeatures + 1, CV_8U, cv::Scalar(cv::ml::VAR_ORDERED));
  const cv::Ptr<cv::ml::TrainData> data =
      cv::ml::TrainData::create(train.x, cv::ml::ROW_SAMPLE, responses, cv::noArray(),
                                cv::noArray(), cv::noArray(), var_type);
  row.train_s.push_back(Seconds([&] { trees->train(data); }));
  cv::Mat predicted;
  const double predict_s = Seconds([&] { trees->predict(test.x, predicted); });
  row.predict_ms_per_1000.push_back(1000.0 * predict_s * 1000.0 / test.x.rows);
  row.mse.push_back(
      Mse(std::vector<float>(predicted.begin<float>(), predicted.end<float>()), test.y));
  const auto dir = std::filesystem::temp_directory_path();
  const std::string yml = (dir / "bench_rtrees.yml").string();
  const std::string gz = (dir / "bench_rtrees.yml.gz").string();
  trees->save(yml);
  trees->save(gz);
  row.bytes = static_cast<double>(std::filesystem::file_size(yml));
  row.bytes_gz = static_cast<double>(std::filesystem::file_size(gz));
  row.load_ms.push_back(1000.0 * Seconds([&] { cv::ml::RTrees::load(yml); }));
  std::filesystem::remove(yml);
  std::filesystem::remove(gz);
}

}  // namespace

int main(int argc, char** argv) {
  const int repeats = argc > 1 ? std::max(1, std::atoi(argv[1])) : 3;
  const int train_rows = argc > 2 ? std::max(10, std::atoi(argv[2])) : 20000;
  const Data train = MakeData(train_rows, 1);
  const Data test = MakeData(kTestRows, 2);
  cv::setNumThreads(1);  // RTrees prediction would otherwise use OpenCV's pool
  Row ours1, ours2, opencv;
  for (int i = 0; i < repeats; ++i) {
    Ours(train, test, 1, ours1);
    Ours(train, test, 2, ours2);
    OpenCvRTrees(train, test, opencv);
  }
  std::printf(
      "RandomForest vs cv::ml::RTrees: %d x %d train, %d test, 200 trees, mtry 6, "
      "min leaf/sample count 5; medians of %d repeats\n\n",
      train_rows, kFeatures, kTestRows, repeats);
  std::printf(
      "| forest | train s | predict ms / 1000 rows | size MiB | load ms | held-out MSE |\n");
  std::printf("|---|---|---|---|---|---|\n");
  const double mib = 1024.0 * 1024.0;
  auto print = [&](const char* name, const Row& row, const std::string& size) {
    std::printf("| %s | %.2f | %.2f | %s | %.1f | %.4f |\n", name, Median(row.train_s),
                Median(row.predict_ms_per_1000), size.c_str(), Median(row.load_ms),
                Median(row.mse));
  };
  char size[128];
  std::snprintf(size, sizeof size, "%.2f (binary)", ours1.bytes / mib);
  print("tod::RandomForest, 1 thread", ours1, size);
  print("tod::RandomForest, 2 threads", ours2, size);
  std::snprintf(size, sizeof size, "%.2f (.yml) / %.2f (.yml.gz)", opencv.bytes / mib,
                opencv.bytes_gz / mib);
  print("cv::ml::RTrees (load: .yml)", opencv, size);
  return 0;
}

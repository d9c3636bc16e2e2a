// Batch prediction speed of RandomForest on one thread, for the two forest shapes the pipeline
// runs per frame:
//   * proposal regressor (ALGORITHM.md §6.3): 200 trees, mtry 6, min leaf 5, unlimited depth,
//     trained on 50 000 x 20 synthetic rows, scoring 40 000 proposals;
//   * pixel edge forest (§3.4): 8 trees, mtry floor(49/3), min leaf 5, depth <= 20, trained on
//     100 000 x 49 synthetic rows, scoring 300 000 pixels.
// Compares the per-row Predict loop with PredictBatch (all rows) and PredictBatch on a subset
// (every other row, as the pipeline scores OBDR for the top half by ORDR), checks that all give
// bit-identical results, and prints medians in a table.
// Usage: bench_forest_predict [repeats=5] [cache_dir]
//   cache_dir: trained forests are saved there and reloaded on later runs (training takes a
//   while); without it every run trains afresh.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include "core/base/atomic_file.h"
#include "core/forest/random_forest.h"

namespace {

struct Data {
  cv::Mat1f x;
  std::vector<float> y;
};

// Uniform features; a smooth non-linear target over a few of them plus noise (the rest are
// distractors), or its sign as a 0/1 label for the classifier case.
Data MakeData(int rows, int cols, unsigned seed, bool binary) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<float> uniform(0.f, 1.f);
  std::normal_distribution<float> noise(0.f, 0.1f);
  Data d{cv::Mat1f(rows, cols), std::vector<float>(rows)};
  for (int r = 0; r < rows; ++r) {
    float* x = d.x[r];
    for (int c = 0; c < cols; ++c) x[c] = uniform(gen);
    const float value =
        std::sin(6.f * x[0]) + 2.f * x[1] * x[2] + (x[3] > 0.5f ? 1.f : 0.f) - x[4] + noise(gen);
    d.y[r] = binary ? (value > 0.6f ? 1.f : 0.f) : value;
  }
  return d;
}

double Seconds(const std::function<void()>& work) {
  const auto start = std::chrono::steady_clock::now();
  work();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// CPU time of this thread: the machine is shared, and wall time would count other processes.
double ThreadCpuSeconds(const std::function<void()>& work) {
  timespec start{}, stop{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &start);
  work();
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &stop);
  return static_cast<double>(stop.tv_sec - start.tv_sec) + 1e-9 * (stop.tv_nsec - start.tv_nsec);
}

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

struct Case {
  std::string name;
  int train_rows;
  int features;
  int predict_rows;
  bool binary;
  tod::ForestParams params;
};

tod::RandomForest TrainOrLoad(const Case& c, const std::string& cache_dir) {
  const std::string path =
      cache_dir.empty() ? "" : (std::filesystem::path(cache_dir) / (c.name + ".forest")).string();
  if (!path.empty() && std::filesystem::exists(path)) {
    std::ifstream in(path, std::ios::binary);
    const std::string file((std::istreambuf_iterator<char>(in)), {});
    tod::Result<tod::RandomForest> loaded = tod::DecodeModel<tod::RandomForest>(file, path);
    if (loaded.ok()) return std::move(loaded).value();
    std::fprintf(stderr, "%s; retraining\n", loaded.status().message().c_str());
  }
  const Data train = MakeData(c.train_rows, c.features, 1, c.binary);
  tod::RandomForest forest;
  const double seconds = Seconds(
      [&] { forest = std::move(tod::RandomForest::Fit(train.x, train.y, c.params)).value(); });
  std::fprintf(stderr, "%s: trained in %.1f s (%lld nodes)\n", c.name.c_str(), seconds,
               static_cast<long long>(forest.num_nodes()));
  if (!path.empty()) {
    std::filesystem::create_directories(cache_dir);
    if (!tod::WriteFileAtomically(path, tod::EncodeModel(forest).value()).ok())
      std::fprintf(stderr, "could not cache %s\n", path.c_str());
  }
  return forest;
}

void Run(const Case& c, int repeats, const std::string& cache_dir) {
  const tod::RandomForest forest = TrainOrLoad(c, cache_dir);
  const Data test = MakeData(c.predict_rows, c.features, 2, c.binary);
  std::vector<int> subset;
  for (int r = 0; r < test.x.rows; r += 2) subset.push_back(r);

  std::vector<double> loop_ms, batch_ms, subset_ms;
  std::vector<float> by_loop(test.x.rows), by_batch, by_subset;
  for (int i = 0; i < repeats; ++i) {
    loop_ms.push_back(1000.0 * ThreadCpuSeconds([&] {
                        for (int r = 0; r < test.x.rows; ++r)
                          by_loop[r] = forest.Predict(test.x[r]);
                      }));
    batch_ms.push_back(1000.0 * ThreadCpuSeconds([&] { by_batch = forest.PredictBatch(test.x); }));
    subset_ms.push_back(1000.0 *
                        ThreadCpuSeconds([&] { by_subset = forest.PredictBatch(test.x, subset); }));
  }
  bool identical = by_batch == by_loop && by_subset.size() == subset.size();
  for (std::size_t k = 0; identical && k < subset.size(); ++k) {
    identical = by_subset[k] == by_loop[subset[k]];
  }

  const double loop = Median(loop_ms);
  const double batch = Median(batch_ms);
  const double per_row = 1000.0 / test.x.rows;  // ms -> us per row
  std::printf(
      "| %s | %d | %lld | %d | %d | %.1f (%.2f us/row) | %.1f (%.2f us/row) | %.1fx | %.1f | %s "
      "|\n",
      c.name.c_str(), forest.num_trees(), static_cast<long long>(forest.num_nodes()),
      forest.PredictionBlockRows(), test.x.rows, loop, loop * per_row, batch, batch * per_row,
      loop / batch, Median(subset_ms), identical ? "yes" : "NO");
}

}  // namespace

int main(int argc, char** argv) {
  const int repeats = argc > 1 ? std::max(1, std::atoi(argv[1])) : 5;
  const std::string cache_dir = argc > 2 ? argv[2] : "";

  Case proposals{"proposal regressor", 50000, 20, 40000, false, {}};
  proposals.params.threads = 2;  // training only; prediction is single-threaded
  Case pixels{"pixel edge forest", 100000, 49, 300000, true, {}};
  pixels.params = {.num_trees = 8, .max_features = 0, .min_leaf_size = 5, .max_depth = 20};
  pixels.params.threads = 2;

  std::printf("RandomForest prediction on one thread, medians of %d runs (thread CPU time)\n\n",
              repeats);
  std::printf(
      "| forest | trees | nodes | block rows | rows | Predict loop ms | PredictBatch ms | speed-up "
      "| "
      "PredictBatch on every 2nd row ms | bit-identical |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|\n");
  Run(proposals, repeats, cache_dir);
  Run(pixels, repeats, cache_dir);
  return 0;
}

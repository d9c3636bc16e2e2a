#include "core/modd2/modd2_split.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <numeric>
#include <random>
#include <sstream>

namespace tod {

Modd2Split DrawModd2Split(std::uint64_t seed, double train_fraction) {
  const std::vector<std::string>& names = Modd2SequenceNames();
  const int count = static_cast<int>(names.size());
  std::vector<int> ids(count);
  std::iota(ids.begin(), ids.end(), 1);
  // mt19937_64's output sequence is fixed by the C++ standard; std::shuffle and the standard
  // distributions are not, so the shuffle is spelled out to stay reproducible across libraries.
  std::mt19937_64 rng(seed);
  for (int i = count - 1; i > 0; --i) {
    const int j = static_cast<int>(rng() % static_cast<std::uint64_t>(i + 1));
    std::swap(ids[i], ids[j]);
  }
  const int train_count =
      std::clamp(static_cast<int>(std::lround(train_fraction * count)), 0, count);
  std::vector<int> train_ids(ids.begin(), ids.begin() + train_count);
  std::vector<int> rest_ids(ids.begin() + train_count, ids.end());
  std::sort(train_ids.begin(), train_ids.end());
  std::sort(rest_ids.begin(), rest_ids.end());

  const std::vector<int>& reflections = Modd2ReflectionSequenceIds();
  Modd2Split split;
  split.source = "random split, seed " + std::to_string(seed);
  for (int id : train_ids) split.train.push_back(names[id - 1]);
  for (int id : rest_ids) {
    const bool reflective =
        std::find(reflections.begin(), reflections.end(), id) != reflections.end();
    (reflective ? split.excluded : split.test).push_back(names[id - 1]);
  }
  return split;
}

Result<std::vector<std::string>> SelectModd2Sequences(const Modd2Split& split,
                                                      const std::string& which) {
  if (which == "train") return split.train;
  if (which == "test") return split.test;
  if (which == "all") {
    std::vector<std::string> all = split.train;
    all.insert(all.end(), split.test.begin(), split.test.end());
    all.insert(all.end(), split.excluded.begin(), split.excluded.end());
    std::sort(all.begin(), all.end());
    all.erase(std::unique(all.begin(), all.end()), all.end());
    return all;
  }
  return Status::InvalidArgument("MODDv2 split '" + which +
                                 "' is unknown; expected \"train\", \"test\" or \"all\"");
}

Result<Modd2Split> ReadModd2SplitFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) return Status::NotFound(path + ": cannot open the split file");
  Modd2Split split;
  split.source = path;
  std::string line;
  int line_number = 0;
  while (std::getline(in, line)) {
    ++line_number;
    const std::size_t hash = line.find('#');
    if (hash != std::string::npos) line.erase(hash);
    std::istringstream fields(line);
    std::string role;
    std::string name;
    std::string extra;
    if (!(fields >> role)) continue;  // blank or comment line
    const std::string where = path + ":" + std::to_string(line_number);
    if (!(fields >> name) || (fields >> extra)) {
      return Status::InvalidArgument(where + ": expected \"<train|test|excluded> <sequence>\"");
    }
    if (role == "train") {
      split.train.push_back(name);
    } else if (role == "test") {
      split.test.push_back(name);
    } else if (role == "excluded") {
      split.excluded.push_back(name);
    } else {
      return Status::InvalidArgument(where + ": unknown role '" + role +
                                     "', expected train, test or excluded");
    }
  }
  return split;
}

std::string FormatModd2SplitFile(const Modd2Split& split) {
  std::ostringstream out;
  out << "# MODDv2 sequence split for tod (" << split.source << ")\n";
  for (const std::string& name : split.train) out << "train " << name << "\n";
  for (const std::string& name : split.test) out << "test " << name << "\n";
  for (const std::string& name : split.excluded) out << "excluded " << name << "\n";
  return out.str();
}

}  // namespace tod

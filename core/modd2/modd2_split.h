// MODDv2 sequence splits (ALGORITHM.md §9.2, §10 row 24). The paper splits the 28 sequences at
// random, 30 % for training and 70 % for testing, and removes sequences with reflections from
// testing, but published no list. The repository fixes one split (default_split.cc, versioned);
// a dataset root may carry its own split file, and Modd2Options may override both.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/base/status.h"

namespace tod {

struct Modd2Split {
  std::string source;  // for messages: where the split came from
  std::vector<std::string> train;
  std::vector<std::string> test;
  std::vector<std::string> excluded;  // known sequences used by neither (reflections)
};

// Version tag of the split shipped in default_split.cc; bump it when the lists change.
inline constexpr char kModd2DefaultSplitVersion[] = "modd2-split-v1";
inline constexpr std::uint64_t kModd2DefaultSplitSeed = 2020;
inline constexpr double kModd2TrainFraction = 0.3;
// Optional per-root split file: lines "train <seq>", "test <seq>", "excluded <seq>", '#' comments.
inline constexpr char kModd2SplitFileName[] = "modd2_split.txt";

// The 28 official sequence names, seq01..seq28 (bborja/modd get_seq_details.m).
const std::vector<std::string>& Modd2SequenceNames();
// 1-based ids of the sequences with environmental reflections (get_extreme_conditions.m).
const std::vector<int>& Modd2ReflectionSequenceIds();
// The versioned default split (the literal lists in default_split.cc).
const Modd2Split& DefaultModd2Split();

// The procedure that produced the default split: Fisher-Yates shuffle of ids 1..28 driven by
// std::mt19937_64(seed) (j = rng() % (i + 1), i from 27 down to 1), the first
// round(train_fraction * 28) ids train, the rest test minus reflection sequences (excluded).
// Each list is in sequence-id order.
Modd2Split DrawModd2Split(std::uint64_t seed, double train_fraction = kModd2TrainFraction);

// The sequences of `which` ("train", "test" or "all" = train + test + excluded).
Result<std::vector<std::string>> SelectModd2Sequences(const Modd2Split& split,
                                                      const std::string& which);

// Split files: errors name the file and the line.
Result<Modd2Split> ReadModd2SplitFile(const std::string& path);
std::string FormatModd2SplitFile(const Modd2Split& split);

}  // namespace tod

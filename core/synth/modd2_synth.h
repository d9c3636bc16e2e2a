// Synthetic marine scenes in the exact MODDv2 layout, for end-to-end tests and demos of
// `tod train/eval --format modd2` (never for tuning the method): sky above a slightly tilted,
// wavy horizon, textured water below, small floating objects on the water and a few large ones
// (boats, piers) that straddle the horizon. Frames are JPEG, annotations Level-5 MAT files
// written with libmatio, exactly as the reader expects them.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/base/status.h"
#include "core/base/types.h"
#include "core/modd2/modd2_reader.h"
#include "core/modd2/modd2_split.h"

namespace tod {

struct Modd2SynthFrame {
  cv::Mat3b image;
  Modd2Annotation annotation;        // 1-based, fractional, as written to the MAT file
  std::vector<Box> small_obstacles;  // 0-based pixel boxes of the floating objects, in
                                     // annotation order (rounded w * h >= 25 each)
  std::vector<Box> large_obstacles;  // 0-based pixel boxes touching the area above the horizon
};

inline constexpr int kModd2SynthMinWidth = 64;
inline constexpr int kModd2SynthMinHeight = 48;

// One frame, deterministic for (width, height, seed); smaller sizes are raised to the minimum.
Modd2SynthFrame GenerateModd2SynthFrame(int width, int height, std::uint64_t seed);

// Seed of frame `frame_index` of sequence `sequence_index` in WriteModd2SynthDataset.
std::uint64_t Modd2SynthFrameSeed(std::uint64_t dataset_seed, int sequence_index, int frame_index);

// The sequence names WriteModd2SynthDataset uses for `sequences` sequences (1..28): the first
// round(0.3 * n) (at least 1, and at most n - 1 when n >= 2) come from the default split's train
// list, the others from its test list, then its excluded list.
Modd2Split Modd2SynthSplit(int sequences);

// Writes `sequences` sequences of `frames_per_sequence` frames each under `root`:
//   video_data/<seq>/frames/%08dL.jpg          frames S+1 .. S+frames_per_sequence
//   annotationsV2/<seq>/ground_truth/%08dL.mat frames S .. S+frames_per_sequence (S: no image,
//                                              as in the real data)
//   modd2_split.txt                            Modd2SynthSplit(sequences), so the reader's
//                                              default options open "train" and "test".
// frames_per_sequence may not exceed E - S of any chosen sequence (110 for the shortest).
Status WriteModd2SynthDataset(const std::string& root, int sequences, int frames_per_sequence,
                              int width, int height, std::uint64_t seed);

}  // namespace tod

#include "core/pipeline/superpixel_share.h"

#include <algorithm>

namespace tod {
namespace {

// Paints max(map, value) over the part of `rect` outside `hole` (both in map coordinates).
// map(p) = combine(map(p), value) for the pixels of `rect` outside `hole`.
template <typename Combine>
void PaintOutside(const cv::Rect& rect, const cv::Rect& hole, float value, cv::Mat1f* map,
                  Combine combine) {
  for (int y = rect.y; y < rect.y + rect.height; ++y) {
    float* row = (*map)[y];
    const bool row_in_hole = y >= hole.y && y < hole.y + hole.height && hole.width > 0;
    for (int x = rect.x; x < rect.x + rect.width; ++x) {
      if (row_in_hole && x >= hole.x && x < hole.x + hole.width) {
        x = hole.x + hole.width - 1;  // skip the hole
        continue;
      }
      row[x] = combine(row[x], value);
    }
  }
}

constexpr auto kKeepLarger = [](float a, float b) { return std::max(a, b); };
constexpr auto kAdd = [](float a, float b) { return a + b; };

}  // namespace

SuperpixelShare::SuperpixelShare(const Superpixels& superpixels, const Box& crop)
    : labels_(superpixels.labels),
      crop_{crop.x, crop.y, superpixels.labels.cols, superpixels.labels.rows},
      area_(static_cast<std::size_t>(std::max(0, superpixels.count)) + 1, 0),
      inside_(area_.size(), 0),
      weighted_(area_.size(), 0.f) {
  for (int y = 0; y < labels_.rows; ++y) {
    const int* row = labels_[y];
    for (int x = 0; x < labels_.cols; ++x)
      if (row[x] > 0 && static_cast<std::size_t>(row[x]) < area_.size()) ++area_[row[x]];
  }
}

void SuperpixelShare::WeighSuperpixels(const cv::Rect& on_crop, float value) {
  const int labels = static_cast<int>(area_.size());
  for (int y = on_crop.y; y < on_crop.y + on_crop.height; ++y) {
    const int* row = labels_[y];
    for (int x = on_crop.x; x < on_crop.x + on_crop.width; ++x) {
      const int label = row[x];
      if (label > 0 && label < labels && inside_[label]++ == 0) touched_labels_.push_back(label);
    }
  }
  for (int label : touched_labels_)
    weighted_[label] =
        value * static_cast<float>(inside_[label]) / static_cast<float>(area_[label]);
}

float SuperpixelShare::BoundaryValue(int cx, int cy) const {
  const int labels = static_cast<int>(area_.size());
  auto weight_at = [&](int x, int y) {
    if (x < 0 || y < 0 || x >= labels_.cols || y >= labels_.rows) return 0.f;
    const int label = labels_(y, x);
    return label > 0 && label < labels ? weighted_[label] : 0.f;
  };
  return std::max(std::max(weight_at(cx + 1, cy), weight_at(cx - 1, cy)),
                  std::max(weight_at(cx, cy + 1), weight_at(cx, cy - 1)));
}

void SuperpixelShare::ClearWeights() {
  for (int label : touched_labels_) {
    inside_[label] = 0;
    weighted_[label] = 0.f;
  }
  touched_labels_.clear();
}

template <typename Combine>
void SuperpixelShare::Paint(const Box& box, float value, cv::Mat1f* map, Combine combine) {
  const Box clipped = ClipToImage(box, map->cols, map->rows);
  if (clipped.empty()) return;
  const Box on_crop = Intersect(clipped, crop_);
  PaintOutside(clipped.rect(), on_crop.rect(), value, map, combine);
  if (on_crop.empty()) return;
  const cv::Rect local(on_crop.x - crop_.x, on_crop.y - crop_.y, on_crop.w, on_crop.h);
  WeighSuperpixels(local, value);
  const int labels = static_cast<int>(area_.size());
  for (int ly = local.y; ly < local.y + local.height; ++ly) {
    const int* label_row = labels_[ly];
    float* row = (*map)[ly + crop_.y] + crop_.x;
    for (int lx = local.x; lx < local.x + local.width; ++lx) {
      const int label = label_row[lx];
      const float v = label > 0 && label < labels ? weighted_[label] : BoundaryValue(lx, ly);
      row[lx] = combine(row[lx], v);
    }
  }
  ClearWeights();
}

void SuperpixelShare::PaintMax(const Box& box, float value, cv::Mat1f* map) {
  Paint(box, value, map, kKeepLarger);
}

void SuperpixelShare::PaintAdd(const Box& box, float value, cv::Mat1f* map) {
  Paint(box, value, map, kAdd);
}

}  // namespace tod

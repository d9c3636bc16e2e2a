// RandomForest::Fit for tests whose data are valid by construction: a failure fails the test
// (and gives an empty forest so that the test can go on to report more).
#pragma once

#include <gtest/gtest.h>

#include <utility>
#include <vector>

#include "core/forest/random_forest.h"

namespace tod {

inline RandomForest FittedForest(const cv::Mat1f& features, const std::vector<float>& targets,
                                 const ForestParams& params) {
  Result<RandomForest> fitted = RandomForest::Fit(features, targets, params);
  EXPECT_TRUE(fitted.ok()) << fitted.status().ToString();
  return fitted.ok() ? std::move(fitted).value() : RandomForest();
}

}  // namespace tod

// The wrap-model comparison (`redmax train-wrap --compare`) as a library call: its rows, their
// order and which of them report an error; a network of the wrong surface is refused.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "tools/wrap_training/compare.hpp"
#include "tools/wrap_training/train.hpp"

namespace redmax {
namespace {

TEST(WrapCompare, RowsForEveryModel) {
  WrapCompareOptions o;
  o.type = WrapType::Sphere;
  o.muscles = 4;
  o.points = 3;
  o.min_time_s = 0.001;
  o.nets.push_back({"2x8 (untrained, timing only)", makeTimingWrapNetwork(WrapType::Sphere, parseHidden("2x8"), 1), true});
  const std::vector<WrapCompareRow> rows = compareWrapModels(o);
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows[0].method, "exact library + central differences");
  EXPECT_EQ(rows[0].rms, 0.0);  // the reference
  EXPECT_EQ(rows[1].method.rfind("smooth model", 0), 0u);
  // the smooth model is the exact path outside its band: small, nonzero error at most
  EXPECT_TRUE(std::isfinite(rows[1].rms));
  EXPECT_LT(rows[1].rms, 0.1);
  EXPECT_LE(rows[1].rms, rows[1].max);
  EXPECT_EQ(rows[2].method, "network 2x8 (untrained, timing only)");
  EXPECT_TRUE(std::isnan(rows[2].rms));  // timing only: no error reported
  EXPECT_EQ(rows[2].parameters, makeTimingWrapNetwork(WrapType::Sphere, {8, 8}, 1).parameterCount());
  for (const auto& r : rows) EXPECT_GT(r.us_per_point, 0.0) << r.method;
}

TEST(WrapCompare, RefusesANetworkOfAnotherSurface) {
  WrapCompareOptions o;
  o.type = WrapType::Ellipsoid;  // 10 inputs; a cylinder network has 8
  o.muscles = 1;
  o.points = 1;
  o.nets.push_back({"cyl", makeTimingWrapNetwork(WrapType::Cylinder, {4}, 1), true});
  EXPECT_THROW(compareWrapModels(o), std::invalid_argument);
  o.nets.clear();
  o.muscles = 0;
  EXPECT_THROW(compareWrapModels(o), std::invalid_argument);
}

}  // namespace
}  // namespace redmax

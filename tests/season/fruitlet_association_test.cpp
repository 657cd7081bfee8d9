// Fruitlets followed from one visit to the next on constructed clusters: shifted and grown,
// one gone, one new, a shrunken impostor, and a merged outline.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "fvp/host/season/fruitlet_association.h"

namespace fvp::host::season {
namespace {

// Five fruitlets of a cluster, about 12 mm apart, in the tag's frame.
std::vector<VisitFruitlet> cluster() {
  return {{{0.000, 0.00, 0.05}, 6.5},
          {{0.012, 0.00, 0.05}, 6.0},
          {{-0.012, 0.00, 0.05}, 5.8},
          {{0.000, 0.012, 0.05}, 7.1},
          {{0.000, -0.012, 0.05}, 5.5}};
}

// The cluster four days on: every stem drooped 2 mm, every fruitlet grown 3 mm but the
// fourth (stopped: it will drop), listed in another order.
std::vector<VisitFruitlet> fourDaysOn(const std::vector<VisitFruitlet>& earlier,
                                      const std::vector<int>& order) {
  std::vector<VisitFruitlet> later;
  for (const int i : order) {
    VisitFruitlet f = earlier[std::size_t(i)];
    f.center_tag_m.z() -= 0.002;
    f.size_mm += i == 3 ? 0.1 : 3.0;
    later.push_back(f);
  }
  return later;
}

TEST(FruitletAssociation, AShiftedGrownClusterKeepsEveryIdentity) {
  const auto earlier = cluster();
  const std::vector<int> order = {3, 0, 4, 1, 2};
  const Association a = associateFruitlets(earlier, fourDaysOn(earlier, order), 4.0);
  for (std::size_t l = 0; l < order.size(); ++l) {
    EXPECT_EQ(a.earlier_of_later[l], order[l]);
    EXPECT_EQ(a.later_of_earlier[std::size_t(order[l])], int(l));
    EXPECT_GT(a.confidence[std::size_t(order[l])], 0.9) << "fruitlet " << order[l];
  }
}

TEST(FruitletAssociation, OneGoneAndOneNew) {
  const auto earlier = cluster();
  auto later = fourDaysOn(earlier, {0, 1, 2, 4});  // the fourth fell off
  later.push_back({{0.03, 0.03, 0.05}, 6.0});      // one not seen before
  const Association a = associateFruitlets(earlier, later, 4.0);
  EXPECT_EQ(a.later_of_earlier, (std::vector<int>{0, 1, 2, -1, 3}));
  EXPECT_EQ(a.earlier_of_later, (std::vector<int>{0, 1, 2, 4, -1}));
  EXPECT_TRUE(std::isnan(a.confidence[3]));
}

TEST(FruitletAssociation, SizeGatesRefuseAShrunkOrOvergrownNeighbour) {
  // The same place, but 2 mm smaller (a fruitlet does not shrink) or 9 mm larger in 4 days.
  const std::vector<VisitFruitlet> earlier = {{{0, 0, 0.05}, 7.0}};
  EXPECT_EQ(associateFruitlets(earlier, {{{0, 0, 0.05}, 5.0}}, 4.0).later_of_earlier[0], -1);
  EXPECT_EQ(associateFruitlets(earlier, {{{0, 0, 0.05}, 16.0}}, 4.0).later_of_earlier[0], -1);
  EXPECT_EQ(associateFruitlets(earlier, {{{0, 0, 0.05}, 12.0}}, 4.0).later_of_earlier[0], 0);
  // Too far: 9 mm away is another fruitlet.
  EXPECT_EQ(associateFruitlets(earlier, {{{0.009, 0, 0.05}, 8.0}}, 4.0).later_of_earlier[0], -1);
}

TEST(FruitletAssociation, AMergedOutlineTakesOneIdentityWithLowConfidence) {
  // Two touching fruitlets 7 mm apart sized as one, between them, the next visit.
  const std::vector<VisitFruitlet> earlier = {{{-0.0035, 0, 0.05}, 6.5}, {{0.0035, 0, 0.05}, 6.6}};
  const std::vector<VisitFruitlet> later = {{{0.0003, 0, 0.05}, 9.0}};
  const Association a = associateFruitlets(earlier, later, 4.0);
  // The nearer (3.2 mm against 3.8 mm) takes it; the other is left "gone".
  ASSERT_EQ(a.earlier_of_later[0], 1);
  EXPECT_EQ(a.later_of_earlier[0], -1);
  // Nearly a coin flip: the pairing's likelihood against the other's and against neither
  // (a pair at the 8 mm gate), shifts in units of the 2 mm spread.
  const auto likelihood = [](double shift_mm) {
    return std::exp(-0.5 * std::pow(shift_mm / 2, 2));
  };
  EXPECT_NEAR(a.confidence[1],
              likelihood(3.2) / (likelihood(3.2) + likelihood(3.8) + likelihood(8.0)), 1e-9);
  EXPECT_LT(a.confidence[1], 0.7);
}

// Each earlier fruitlet's growth gate counts from its own last size: 5 mm of growth is
// possible in 7 days, not in 1.
TEST(FruitletAssociation, EachFruitletsGrowthGateIsItsOwn) {
  const std::vector<VisitFruitlet> earlier = {{{0, 0, 0.05}, 7.0}, {{0.004, 0, 0.05}, 7.0}};
  const std::vector<VisitFruitlet> later = {{{0.001, 0, 0.05}, 12.0}};
  const Association a = associateFruitlets(earlier, later, std::vector<double>{1.0, 7.0});
  EXPECT_EQ(a.earlier_of_later[0], 1);  // the farther one, seen 7 days ago
  EXPECT_THROW(associateFruitlets(earlier, later, std::vector<double>{1.0}), std::invalid_argument);
}

TEST(FruitletAssociation, BadSettingsAreRefused) {
  AssociationConfig bad;
  bad.center_sigma_m = 0.0;
  EXPECT_THROW(associateFruitlets({}, {}, 4.0, bad), std::invalid_argument);
  EXPECT_THROW(associateFruitlets({}, {}, -1.0), std::invalid_argument);
  EXPECT_THROW(associateFruitlets({}, {}, NAN), std::invalid_argument);
  EXPECT_TRUE(associateFruitlets({}, {}, 0.0).later_of_earlier.empty());
}

}  // namespace
}  // namespace fvp::host::season

// A restart of the refinement told the minimum already found (lib/src/fit/least_squares.h,
// KnownMinimum) stops where it comes back to it, and only there: on random few-point scenes,
// every restart from the image centre and from each edge midpoint's principal point is run with
// and without the known minimum. A run told it ends either exactly as the run not told (the same
// iterates: it never came near the known minimum), or stopped at the known minimum where the run
// not told converges to that same minimum -- never stopped where the other goes on to another
// minimum. Where the known minimum settled a part in 1e8 above the bottom of a valley flat to its
// rounding, the run not told can settle lower by more than the refinement stage's rounding bound
// at the same minimum (within 1e-4 px of it): the stop keeps the known one there, a rate.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "camproj/synth.h"
#include "fit/closed_form.h"
#include "fit/common.h"
#include "fit/least_squares.h"
#include "fit/scene.h"
#include "fit/start.h"
#include "seeds.h"

namespace camproj {
namespace {

using internal::KnownMinimum;
using internal::LeastSquaresOutcome;

// A cost lower than the known minimum's by more than this would have replaced it (the refinement
// stage's own bound for "the same cost", kLowerByRounding).
constexpr double kSameCost = internal::kLowerByRounding;
// And their cameras, at the fitted points: the determination check's bound for the same minimum
// refitted (fit/determination.cc, kSameMinimumPx), above the settled runs' spread where the
// cost is flat to its rounding (seen: 1.4e-6 - 5e-6 px at costs 1e-11 apart, 6-7 points).
constexpr double kSamePixelsPx = 1e-3;

// The largest distance between where two outcomes put the scene's points (px).
double PixelDistancePx(const internal::Scene& scene, const LeastSquaresOutcome& a,
                       const LeastSquaresOutcome& b) {
  const Intrinsics ka = a.model.ToIntrinsics();
  const Intrinsics kb = b.model.ToIntrinsics();
  double largest = 0.0;
  for (const Eigen::Vector3d& x : scene.points) {
    const Eigen::Vector3d pa = a.rotation * (x - a.center);
    const Eigen::Vector3d pb = b.rotation * (x - b.center);
    const Eigen::Vector2d ua(ka.fx * pa.x() / pa.z() + ka.skew * pa.y() / pa.z() + ka.cx,
                             ka.fy * pa.y() / pa.z() + ka.cy);
    const Eigen::Vector2d ub(kb.fx * pb.x() / pb.z() + kb.skew * pb.y() / pb.z() + kb.cx,
                             kb.fy * pb.y() / pb.z() + kb.cy);
    largest = std::max(largest, (ua - ub).norm());
  }
  return largest;
}

TEST(KnownMinimumTest, ARestartStopsOnlyWhereItComesBackToTheKnownMinimum) {
  constexpr int kSeeds = 1000;
  int restarts = 0, stopped = 0, elsewhere = 0, violations = 0, settled_lower = 0;
  for (int seed = 0; seed < kSeeds; ++seed) {
    SynthOptions synth;
    synth.seed = testing::Seed(static_cast<uint64_t>(seed));
    synth.num_points = 6 + seed % 7;  // 6 ... 12
    synth.object = seed % 3 == 0 ? SynthObject::kBox : SynthObject::kCloud;
    synth.image_size = ImageSize{1920, 1080};
    synth.fovy_deg = 30.0 + seed % 4 * 10.0;
    synth.principal_point_offset = Eigen::Vector2d(0.0, seed % 2 == 0 ? 0.5 : 0.0);
    synth.noise_px = seed % 5 == 0 ? 2.0 : 0.5;
    const SynthScene s = SynthesizeScene(synth);
    FitOptions options;  // focal, aspect and principal point free
    const internal::Clock::time_point now = internal::Clock::now();
    internal::Scene scene;
    internal::Start start;
    try {
      scene = internal::ValidateScene(s.correspondences.points_in_world, s.correspondences.pixels,
                                      synth.image_size, options);
      start = internal::ClosedFormStart(scene, options, now);
    } catch (const SceneError&) {
      continue;
    }
    const LeastSquaresOutcome best =
        internal::RefineLeastSquares(scene.points, scene.pixels, start.camera.rotation,
                                     start.camera.center, start.model, options, now);
    if (!best.ok || !best.converged) continue;
    const KnownMinimum known{best.rotation, best.center, best.model.value, best.normal.cost};
    std::vector<Eigen::Vector2d> principal_points = internal::EdgeMidpoints(scene.image_size, 0.0);
    principal_points.push_back(scene.model.value[2] * Eigen::Vector2d::UnitX() +
                               scene.model.value[3] * Eigen::Vector2d::UnitY());
    for (const Eigen::Vector2d& principal_point : principal_points) {
      internal::Model model = start.model;
      model.value[2] = principal_point.x();
      model.value[3] = principal_point.y();
      internal::StartCamera pose;
      if (!internal::PnpStart(scene.points, scene.pixels, model.ToIntrinsics(), &pose)) continue;
      auto refine = [&](const KnownMinimum* told) {
        return internal::RefineLeastSquares(
            scene.points, scene.pixels, pose.rotation, pose.center, model, options, now,
            internal::kMaxLeastSquaresRounds, internal::PolishFirst::kNo,
            internal::PolishUntil::kSettled, std::numeric_limits<double>::infinity(), told);
      };
      const LeastSquaresOutcome free_run = refine(nullptr);
      const LeastSquaresOutcome told_run = refine(&known);
      ++restarts;
      if (told_run.at_known_minimum) {
        ++stopped;
        // Only where the run not told ends at the same minimum.
        const bool same =
            free_run.ok && PixelDistancePx(scene, free_run, best) <= kSamePixelsPx;
        if (same && free_run.normal.cost < best.normal.cost * (1.0 - kSameCost)) ++settled_lower;
        if (!same) {
          ++violations;
          ADD_FAILURE() << "seed " << seed << ": stopped at the known minimum (cost "
                        << best.normal.cost << ") where the run not told ends at cost "
                        << free_run.normal.cost << ", "
                        << PixelDistancePx(scene, free_run, best) << " px from it";
        }
        EXPECT_FALSE(told_run.ok) << "seed " << seed;
      } else {
        // Never near it: the same run, iterate for iterate.
        ++elsewhere;
        EXPECT_EQ(told_run.ok, free_run.ok) << "seed " << seed;
        EXPECT_EQ(told_run.iterations, free_run.iterations) << "seed " << seed;
        EXPECT_EQ(told_run.normal.cost, free_run.normal.cost) << "seed " << seed;
      }
    }
  }
  std::printf("[ INFO     ] %d restarts: %d stopped at the known minimum, %d ran their course\n",
              restarts, stopped, elsewhere);
  EXPECT_EQ(violations, 0);
  // Seen: 4 of 46 727 stops (one scene's four restarts) at seed offsets 0, 7, 1000, 2000, 3000,
  // 5000, 12345, 65536, 99999 and 123456.
  testing::ExpectRate("restarts stopped where the run not told settles lower at the same minimum",
                      settled_lower, stopped, 1e-3);
  // The stop must act, or this test shows nothing: most restarts come back (measured: ~70 %).
  EXPECT_GT(stopped, restarts / 3);
}

}  // namespace
}  // namespace camproj

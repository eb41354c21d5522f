// bench --stage-cost (stage_cost.h). Public API of 40af1d1 only: see the header.
#include "stage_cost.h"

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "camproj/fit.h"
#include "camproj/model_select.h"
#include "camproj/synth.h"
#include "point_counts.h"

namespace camproj {
namespace bench {
namespace {

using Clock = std::chrono::steady_clock;

const char* kUsage =
    "bench --stage-cost: the default path (FitCameraAuto, default options) on clean scenes.\n"
    "\n"
    "Usage: bench --stage-cost [--n N,N,...] [--seeds K] [--one-fit]\n"
    "\n"
    "Fits camproj::SynthesizeScene clouds (1920x1080, fovy 45 deg, sigma 0.5 px; a centred\n"
    "camera and a projector with its principal point at the bottom edge; seeds 1..K, so 2K\n"
    "scenes per N) and prints per N: scenes, refusals, the median wall time per fit and a digest\n"
    "of every answer and refusal (equal digests: the same cameras and messages). Run it under\n"
    "callgrind for instruction counts: scripts/bench_stage_cost.sh, docs/bench/stage_cost.md.\n"
    "\n"
    "  --n N,N,...  point counts (default 6,8,12,20,100,1000)\n"
    "  --seeds K    seeds per N and camera (default 20 for N <= 20, 10 for N <= 100, 3 above)\n"
    "  --one-fit    instead, one fit of OpenCV's model from scratch on the same scenes\n"
    "               (FitCamera: focal and principal point free, aspect 1, no covariance; apps/bench's\n"
    "               ours-refine)\n"
    "\n"
    "Example:\n"
    "  valgrind --tool=callgrind --toggle-collect='camproj::FitCameraAuto*' \\\n"
    "      build/release/apps/bench --stage-cost --n 20\n";

int DefaultSeeds(int n) { return n <= 20 ? 20 : n <= 100 ? 10 : 3; }

// FNV-1a over bytes: the digest of the answers.
void Mix(uint64_t* hash, const void* data, size_t size) {
  const unsigned char* bytes = static_cast<const unsigned char*>(data);
  for (size_t i = 0; i < size; ++i) {
    *hash ^= bytes[i];
    *hash *= 1099511628211ULL;
  }
}

void MixDouble(uint64_t* hash, double value) { Mix(hash, &value, sizeof value); }

struct Row {
  int n = 0;
  int scenes = 0;
  int refused = 0;
  double time_median_us = 0.0;
  uint64_t digest = 1469598103934665603ULL;
};

// One fit of OpenCV's model from scratch (apps/bench's ours-refine): FitCamera's closed-form start
// and refinement, no covariance.
FitResult OneFit(const SynthScene& scene, const ImageSize& image_size) {
  FitOptions options;
  options.aspect = ParameterMode::Default();  // 1
  options.compute_uncertainty = false;
  return FitCamera(scene.correspondences.points_in_world, scene.correspondences.pixels,
                   image_size, options);
}

Row Measure(int n, int seeds, bool one_fit) {
  Row row;
  row.n = n;
  std::vector<double> times_us;
  for (int seed = 1; seed <= seeds; ++seed) {
    for (const double offset_y : {0.0, 0.5}) {
      SynthOptions synth;
      synth.seed = static_cast<uint64_t>(seed);
      synth.num_points = n;
      synth.object = SynthObject::kCloud;
      synth.image_size = ImageSize{1920, 1080};
      synth.fovy_deg = 45.0;
      synth.principal_point_offset = Eigen::Vector2d(0.0, offset_y);
      synth.noise_px = 0.5;
      const SynthScene scene = SynthesizeScene(synth);
      const Clock::time_point start = Clock::now();
      try {
        const FitResult fit =
            one_fit ? OneFit(scene, synth.image_size)
                    : FitCameraAuto(scene.correspondences.points_in_world,
                                    scene.correspondences.pixels, synth.image_size);
        times_us.push_back(std::chrono::duration<double, std::micro>(Clock::now() - start).count());
        Mix(&row.digest, fit.model.data(), fit.model.size());
        const Intrinsics& k = fit.camera.intrinsics;
        for (const double v : {k.fx, k.fy, k.cx, k.cy, k.skew, k.k1, k.k2, fit.rms_px}) {
          MixDouble(&row.digest, v);
        }
        const Eigen::Vector3d& t = fit.camera.cam_from_world.translation;
        for (int i = 0; i < 3; ++i) MixDouble(&row.digest, t(i));
      } catch (const std::exception& e) {
        times_us.push_back(std::chrono::duration<double, std::micro>(Clock::now() - start).count());
        ++row.refused;
        Mix(&row.digest, e.what(), std::strlen(e.what()));
      }
      ++row.scenes;
    }
  }
  std::sort(times_us.begin(), times_us.end());
  const size_t m = times_us.size();
  row.time_median_us = m == 0 ? 0.0 : 0.5 * (times_us[(m - 1) / 2] + times_us[m / 2]);
  return row;
}

}  // namespace

int StageCostMain(int argc, char** argv) {
  std::vector<int> counts = {6, 8, 12, 20, 100, 1000};
  int seeds = 0;  // 0: DefaultSeeds
  bool one_fit = false;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::cerr << "bench: " << arg << " needs a value\n" << kUsage;
        std::exit(1);
      }
      return argv[++i];
    };
    if (arg == "--stage-cost") continue;
    if (arg == "-h" || arg == "--help") {
      std::cout << kUsage;
      return 0;
    } else if (arg == "--n") {
      if (!ParsePointCounts(value(), &counts)) return 1;
    } else if (arg == "--one-fit") {
      one_fit = true;
    } else if (arg == "--seeds") {
      seeds = std::atoi(value().c_str());
      if (seeds < 1) {
        std::cerr << "bench: --seeds must be a positive integer\n";
        return 1;
      }
    } else {
      std::cerr << "bench: unknown argument \"" << arg << "\"\n" << kUsage;
      return 1;
    }
  }
  std::printf("n,scenes,refused,time_median_us,digest\n");
  for (const int n : counts) {
    const Row row = Measure(n, seeds > 0 ? seeds : DefaultSeeds(n), one_fit);
    std::printf("%d,%d,%d,%.1f,%016llx\n", row.n, row.scenes, row.refused, row.time_median_us,
                static_cast<unsigned long long>(row.digest));
    std::fflush(stdout);
  }
  return 0;
}

}  // namespace bench
}  // namespace camproj

#ifdef CAMPROJ_STAGE_COST_MAIN
int main(int argc, char** argv) { return camproj::bench::StageCostMain(argc, argv); }
#endif

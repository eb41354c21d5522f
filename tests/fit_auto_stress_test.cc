// FitCameraAuto (model_select.h) with default options on 2000 seeded, well-formed but adversarial
// scenes (issue #10): extreme world scales and offsets, near-duplicate points, collinear and
// coplanar subsets, pixels outside the image, few points, one bad point, extreme intrinsics.
//
// The contract, per scene: FitCameraAuto returns a camera or throws SceneError with a reason
// other than kNumerical ("a bug: please report it"); nothing else (the command line would exit
// 2). A refusal says what to do apart (SceneError::fix, the command line's "to fix:" line): not
// empty, what() is why() + ". " + fix(), and the fix stands alone (no "that pixel", "near it" or
// "those points" pointing back into the why). A returned camera
//   - passed the consistency gate (FitResult::consistency);
//   - keeps at least half of the points (a minority consensus is refused);
//   - reports the rms_px a reader of the camera file recomputes: PixelFromWorld over the kept
//     points (not in FitResult::outliers), every one of them in front of the camera;
//   - survives CameraToJsonText -> CameraFromJsonText with the same RMS.
// And a scene scaled by 2^k gives the same outcome bit for bit; a scene moved far from the
// origin gives the same outcome (camera with the same model, or refusal with the same reason)
// as before the move, or is refused as too far for double precision (kNonFiniteInput).
// Any violation fails the test with its seed and one line; CAMPROJ_STRESS_SEED=N reruns seed N
// alone and prints its scene and outcome. CAMPROJ_STRESS_SCENES=K runs seeds 0 ... K-1 instead of
// all 2000: scripts/test.sh --sanitize sets K = 400, 50 scenes of each category
// (categories cycle with the seed) for ASan and UBSan to watch, at a fifth of the cost; the
// contract itself is checked on all 2000 in the Release build.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <optional>
#include <random>
#include <string>
#include <thread>
#include <time.h>
#include <vector>

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "camproj/camera.h"
#include "camproj/camera_file.h"
#include "camproj/fit.h"
#include "camproj/model_select.h"
#include "seeds.h"
#include "test_scenes.h"

namespace camproj {
namespace {

using testing::LogUniform;
using testing::Uniform;

constexpr double kPi = 3.14159265358979323846;
constexpr int kNumScenes = 2000;
constexpr int kThreads = 2;
// Scenes have 6 to kMaxPoints points (4 to kMaxPoints in the point-count category): enough for
// every path of the pipeline (the exhaustive outlier search ends at 12 points, LO-RANSAC above),
// small enough for 2000 scenes under ASan in CI.
constexpr int kMaxPoints = 60;

// rms_px against the RMS recomputed here. FitCameraAuto computes rms_px from the returned camera
// with PixelFromWorld, the same per-point pixels as here; only the order of the sum and |r|^2
// against r.squaredNorm() may differ: (N + 2) u <= 1.4e-14 relative for N <= 2 kMaxPoints points
// (u = 1.1e-16; near-duplicates doubles a scene). kExactRelative (1e-12) is that with a margin.
// No absolute floor: an RMS computed elsewhere (in the fitter's centred frame) differs by far
// more once the world is offset.
constexpr double kRmsRelative = testing::kExactRelative;
// The camera file's RMS against the returned camera's: exactly equal. The file writes every
// double as the shortest text that reads back to it (camera_file.h: "they round-trip exactly"),
// so the camera read back is the same numbers and its RMS the same computation.

enum Category {
  kExtremeScale,     // world coordinates times 2^-660 ... 2^660 (1e-199 ... 1e199)
  kLargeOffset,      // world moved by 1e3 ... 1e12 scene sizes
  kNearDuplicates,   // points repeated exactly or within 1e-12 relative
  kDegenerateShape,  // points on a line, a plane, a plane and one more, a thin slab
  kWildPixels,       // pixels outside the image or ~1e9 px, image sizes 1x1 ... 20000x20000
  kPointCount,       // 4 ... kMaxPoints points, mostly 4 to 7
  kOneBadPoint,      // one mis-click, point at the camera centre or behind it, or swapped pair
  kWildIntrinsics,   // field of view 0.01 ... 179 deg, principal point far off, aspect, skew
  kNumCategories,
};

const char* const kCategoryNames[kNumCategories] = {
    "extreme-scale", "large-offset", "near-duplicates", "degenerate-shape",
    "wild-pixels",   "point-count",  "one-bad-point",   "wild-intrinsics"};

struct StressScene {
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector2d> pixels;
  ImageSize size;
  std::string description;  // what was generated, for a failure's line
  // The points before an exact scaling (extreme-scale: the outcome must be the same, bit for
  // bit) or a move (large-offset: the same outcome, or the refusal of coordinates whose offset
  // leaves too few digits).
  std::optional<std::vector<Eigen::Vector3d>> unscaled_points;
  std::optional<std::vector<Eigen::Vector3d>> unmoved_points;
};

std::string Format(const char* format, double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, format, value);
  return buffer;
}

int UniformInt(std::mt19937_64& rng, int lo, int hi) {
  return std::uniform_int_distribution<int>(lo, hi)(rng);
}

bool OneIn(std::mt19937_64& rng, int k) { return UniformInt(rng, 1, k) == 1; }

// Log-uniform integer in [lo, hi]: as many scenes at 6-12 points as at 12-60.
int NumPoints(std::mt19937_64& rng, int lo = 6, int hi = kMaxPoints) {
  return std::min(hi, static_cast<int>(LogUniform(rng, lo, hi + 1.0)));
}

// Pixel noise 0-1 px, exactly 0 in a fifth of the scenes (residuals at rounding level).
double PixelNoise(std::mt19937_64& rng) { return OneIn(rng, 5) ? 0.0 : Uniform(rng, 0.0, 1.0); }

Eigen::Vector3d RandomDirection(std::mt19937_64& rng) {
  std::normal_distribution<double> normal;
  return testing::DrawVector3([&] { return normal(rng); }).normalized();
}

Eigen::Vector2d Gaussian2(std::mt19937_64& rng, double sigma) {
  std::normal_distribution<double> normal(0.0, sigma);
  return {normal(rng), normal(rng)};
}

Eigen::Vector3d Centroid(const std::vector<Eigen::Vector3d>& points) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const auto& x : points) sum += x;
  return sum / static_cast<double>(points.size());
}

// The largest distance of a point from the centroid.
double SceneSize(const std::vector<Eigen::Vector3d>& points) {
  const Eigen::Vector3d centroid = Centroid(points);
  double size = 0.0;
  for (const auto& x : points) size = std::max(size, (x - centroid).norm());
  return size;
}

// The pinhole formula applied whatever the sign of the depth (a point behind the camera lands
// where its reflection through the centre would).
Eigen::Vector2d ThroughProjection(const testing::RandomCamera& camera, const Eigen::Vector3d& x) {
  const Eigen::Vector3d p = camera.cam_from_world * x;
  const Intrinsics& k = camera.intrinsics;
  return {k.fx * p.x() / p.z() + k.skew * p.y() / p.z() + k.cx, k.fy * p.y() / p.z() + k.cy};
}

// A world point seen at `pixel`, 2 to 4 units in front of the camera.
Eigen::Vector3d PointAt(std::mt19937_64& rng, const testing::RandomCamera& camera,
                        const Eigen::Vector2d& pixel) {
  return testing::WorldPointAtPixel(camera, pixel, Uniform(rng, 2.0, 4.0));
}

// A camera or projector as the default path models them: square pixels, no skew, the principal
// point anywhere within an image size of the image (a projector's lens shift). (Aspect and skew
// are in the wild-intrinsics category only: every scene the default screen -- pose + focal +
// principal point -- does not explain goes through the outlier search, the costly path.)
testing::RandomCamera ProjectorCamera(std::mt19937_64& rng) {
  testing::RandomCameraOptions options;
  options.max_aspect_ratio = 1.0;
  options.max_skew_ratio = 0.0;
  return testing::MakeRandomCamera(rng, options);
}

// A camera a plane determines with the default model: the principal point at the image centre
// (a plane determines at most two of focal, aspect and principal point; the screen of a plane
// seen by a shifted lens finds no camera, and the outlier search then costs ~0.5 s).
testing::RandomCamera CentredCamera(std::mt19937_64& rng) {
  testing::RandomCamera camera = ProjectorCamera(rng);
  camera.intrinsics.cx = 0.5 * (camera.size.width - 1.0);
  camera.intrinsics.cy = 0.5 * (camera.size.height - 1.0);
  return camera;
}

// A scene of `n` points in front of `camera`, seen inside its image with `noise` px.
StressScene GoodScene(std::mt19937_64& rng, const testing::RandomCamera& camera, int n,
                      double noise, bool planar = false) {
  testing::SceneOptions options;
  options.num_points = n;
  options.pixel_noise = noise;
  options.planar = planar;
  const testing::Scene scene = testing::MakeScene(rng, camera, options);
  StressScene s;
  s.points = scene.points_in_world;
  s.pixels = scene.observed_pixels;
  s.size = camera.size;
  s.description = "N " + std::to_string(n) + (planar ? " coplanar" : "") + ", noise " +
                  Format("%.2f", noise) + " px";
  return s;
}

StressScene ExtremeScale(std::mt19937_64& rng) {
  const testing::RandomCamera camera = ProjectorCamera(rng);
  const double noise = PixelNoise(rng);  // before the count (testing::DrawVector3 says why)
  StressScene s = GoodScene(rng, camera, NumPoints(rng), noise);
  s.unscaled_points = s.points;
  // World times 2^k, k in [-660, 660] (1e-199 ... 1e199; the extremes and 2^+-40 ~ 1e+-12 named
  // in half the scenes): exact, so the fit must not change at all.
  const int named[] = {-660, -40, 40, 660};
  const int k = OneIn(rng, 2) ? named[UniformInt(rng, 0, 3)] : UniformInt(rng, -660, 660);
  for (auto& x : s.points) x = std::ldexp(1.0, k) * x;
  s.description += ", world x 2^" + std::to_string(k);
  return s;
}

StressScene LargeOffset(std::mt19937_64& rng) {
  const testing::RandomCamera camera = ProjectorCamera(rng);
  const double noise = PixelNoise(rng);  // before the count (testing::DrawVector3 says why)
  StressScene s = GoodScene(rng, camera, NumPoints(rng), noise);
  s.unmoved_points = s.points;
  const double named[] = {1e3, 1e6, 1e9, 1e12};
  const double factor =
      OneIn(rng, 3) ? named[UniformInt(rng, 0, 3)] : std::pow(10.0, Uniform(rng, 3.0, 12.0));
  // Along a world axis (round in two coordinates) or in any direction.
  const Eigen::Vector3d direction =
      OneIn(rng, 3) ? Eigen::Vector3d::Unit(UniformInt(rng, 0, 2)) : RandomDirection(rng);
  const Eigen::Vector3d offset = factor * SceneSize(s.points) * direction;
  for (auto& x : s.points) x += offset;
  s.description += ", offset " + Format("%.3g", factor) + " scene sizes";
  return s;
}

StressScene NearDuplicates(std::mt19937_64& rng) {
  const testing::RandomCamera camera = ProjectorCamera(rng);
  const int n = NumPoints(rng);
  const double noise = PixelNoise(rng);
  StressScene s = GoodScene(rng, camera, n, noise);
  std::normal_distribution<double> normal;
  auto nudged = [&](const Eigen::Vector3d& x) {  // moved by ~1e-12 of its norm
    const Eigen::Vector3d step = testing::DrawVector3([&] { return normal(rng); });
    return Eigen::Vector3d(x + 1e-12 * x.norm() * step);
  };
  switch (UniformInt(rng, 0, 3)) {
    case 0: {  // some points again, exactly (same point, same pixel)
      const int repeats = UniformInt(rng, 1, n);
      for (int r = 0; r < repeats; ++r) {
        const int i = UniformInt(rng, 0, n - 1);
        s.points.push_back(s.points[i]);
        s.pixels.push_back(s.pixels[i]);
      }
      s.description += ", " + std::to_string(repeats) + " exact repeats";
      break;
    }
    case 1: {  // some points again, nudged, with their own noisy pixel
      const int repeats = UniformInt(rng, 1, n);
      for (int r = 0; r < repeats; ++r) {
        const int i = UniformInt(rng, 0, n - 1);
        s.points.push_back(nudged(s.points[i]));
        s.pixels.push_back(ThroughProjection(camera, s.points.back()) + Gaussian2(rng, noise));
      }
      s.description += ", " + std::to_string(repeats) + " repeats within 1e-12";
      break;
    }
    case 2: {  // only 4 to 7 distinct points, each repeated
      const int distinct = UniformInt(rng, 4, std::min(7, n));
      for (int i = distinct; i < n; ++i) {
        const int j = UniformInt(rng, 0, distinct - 1);
        s.points[i] = s.points[j];
        // The same click again, or a second click of the same point.
        s.pixels[i] = OneIn(rng, 2) ? s.pixels[j]
                                    : Eigen::Vector2d(ThroughProjection(camera, s.points[j]) +
                                                      Gaussian2(rng, noise));
      }
      s.description += ", only " + std::to_string(distinct) + " distinct";
      break;
    }
    default:  // every point twice, nudged, same pixel
      for (int i = 0; i < n; ++i) {
        s.points.push_back(nudged(s.points[i]));
        s.pixels.push_back(s.pixels[i]);
      }
      s.description += ", every point twice within 1e-12";
  }
  return s;
}

StressScene DegenerateShape(std::mt19937_64& rng) {
  const testing::RandomCamera camera = CentredCamera(rng);
  const int n = NumPoints(rng);
  const double noise = PixelNoise(rng);
  // 0, 1: points on a line; 2: all on a plane; 3: all but one; 4: a thin slab.
  const int variant = UniformInt(rng, 0, 4);
  StressScene s = GoodScene(rng, camera, n, noise, /*planar=*/variant >= 2);
  auto observe = [&](const Eigen::Vector3d& x) {
    return Eigen::Vector2d(ThroughProjection(camera, x) + Gaussian2(rng, noise));
  };
  if (variant <= 1) {  // half the points (0) or all (1) on a line through the viewed volume
    const Eigen::Vector3d a = PointAt(rng, camera, testing::RandomPixelInImage(rng, camera.size));
    const Eigen::Vector3d b = PointAt(rng, camera, testing::RandomPixelInImage(rng, camera.size));
    const int on_line = variant == 0 ? n / 2 : n;
    for (int i = 0; i < on_line; ++i) {
      s.points[i] = a + Uniform(rng, 0.0, 1.0) * (b - a);
      s.pixels[i] = observe(s.points[i]);
    }
    s.description += ", " + std::to_string(on_line) + " on a line";
  } else if (variant == 3) {  // and one point off the plane
    s.points.back() = PointAt(rng, camera, testing::RandomPixelInImage(rng, camera.size));
    s.pixels.back() = observe(s.points.back());
    s.description += " but one";
  } else if (variant == 4) {  // a slab 1e-12 ... 1e-3 of the plane's size thick
    const Eigen::Vector3d normal_direction =
        (s.points[1] - s.points[0]).cross(s.points[2] - s.points[0]).normalized();
    const double thickness = LogUniform(rng, 1e-12, 1e-3) * SceneSize(s.points);
    std::normal_distribution<double> normal;
    for (size_t i = 0; i < s.points.size(); ++i) {
      s.points[i] += thickness * normal(rng) * normal_direction;
      s.pixels[i] = observe(s.points[i]);
    }
    s.description += ", thickened by " + Format("%.2g", thickness);
  }
  return s;
}

StressScene WildPixels(std::mt19937_64& rng) {
  testing::RandomCamera camera = ProjectorCamera(rng);
  const int n = NumPoints(rng);
  const double noise = PixelNoise(rng);
  const double w = camera.size.width;
  const double h = camera.size.height;
  StressScene s;
  s.size = camera.size;
  s.description = "N " + std::to_string(n) + ", noise " + Format("%.2f", noise) + " px";
  switch (UniformInt(rng, 0, 3)) {
    case 0: {  // pixels up to `reach` image sizes around the image
      const double reach = LogUniform(rng, 0.5, 10.0);
      for (int i = 0; i < n; ++i) {
        const Eigen::Vector2d pixel =
            testing::DrawVector2([&] { return Uniform(rng, -reach, 1.0 + reach); })
                .cwiseProduct(Eigen::Vector2d(w, h));
        s.points.push_back(PointAt(rng, camera, pixel));
        s.pixels.push_back(pixel + Gaussian2(rng, noise));
      }
      s.description += ", pixels within " + Format("%.2g", reach) + " image sizes of the image";
      break;
    }
    case 1: {  // every pixel shifted by up to 20 image sizes, or by 1e9 px
      // y before x (testing::DrawVector3 says why).
      const double shift_y = OneIn(rng, 4) ? -1e9 : Uniform(rng, -20.0, 20.0) * h;
      const double shift_x = OneIn(rng, 4) ? 1e9 : Uniform(rng, -20.0, 20.0) * w;
      const Eigen::Vector2d shift(shift_x, shift_y);
      s = GoodScene(rng, camera, n, noise);
      for (auto& u : s.pixels) u += shift;
      s.description += ", pixels shifted by (" + Format("%.3g", shift.x()) + ", " +
                       Format("%.3g", shift.y()) + ")";
      break;
    }
    case 2: {  // a focal length of 1e6 ... 1e9 px: the points spread over a virtual image that wide
      const double spread = LogUniform(rng, 1e6, 1e9);
      Intrinsics& k = camera.intrinsics;
      k.fx *= spread / w;
      k.fy *= spread / w;
      k.skew *= spread / w;
      const Eigen::Vector2d principal(k.cx, k.cy);
      for (int i = 0; i < n; ++i) {
        const Eigen::Vector2d pixel =
            principal + spread * testing::DrawVector2([&] { return Uniform(rng, -0.5, 0.5); });
        s.points.push_back(PointAt(rng, camera, pixel));
        s.pixels.push_back(pixel + Gaussian2(rng, noise));
      }
      s.description += ", pixels spread over " + Format("%.2g", spread) + " px";
      break;
    }
    default: {  // image sizes 1x1 ... 20000x20000, the scene filling the image
      camera.size = {std::min(20000, static_cast<int>(LogUniform(rng, 1.0, 20001.0))),
                     std::min(20000, static_cast<int>(LogUniform(rng, 1.0, 20001.0)))};
      if (OneIn(rng, 5)) camera.size = {1, 1};
      if (OneIn(rng, 5)) camera.size = {20000, 20000};
      Intrinsics& k = camera.intrinsics;
      const double fov = Uniform(rng, 10.0, 120.0) * kPi / 180.0;
      k.fx = k.fy = 0.5 * camera.size.width / std::tan(0.5 * fov);
      k.cx = 0.5 * (camera.size.width - 1.0);
      k.cy = 0.5 * (camera.size.height - 1.0);
      k.skew = 0.0;
      s = GoodScene(rng, camera, n, noise);
      s.description += ", image " + std::to_string(camera.size.width) + "x" +
                       std::to_string(camera.size.height);
    }
  }
  return s;
}

StressScene PointCount(std::mt19937_64& rng) {
  const bool planar = OneIn(rng, 5);
  const testing::RandomCamera camera = planar ? CentredCamera(rng) : ProjectorCamera(rng);
  const int n = OneIn(rng, 3) ? NumPoints(rng, 4, kMaxPoints) : UniformInt(rng, 4, 7);
  return GoodScene(rng, camera, n, PixelNoise(rng), planar);
}

StressScene OneBadPoint(std::mt19937_64& rng) {
  const testing::RandomCamera camera = ProjectorCamera(rng);
  const int n = NumPoints(rng);
  StressScene s = GoodScene(rng, camera, n, PixelNoise(rng));
  const int i = UniformInt(rng, 0, n - 1);
  switch (UniformInt(rng, 0, 3)) {
    case 0: {  // a mis-click: 20 to 500 px off; the direction drawn before the distance
               // (testing::DrawVector3 says why)
      const Eigen::Vector2d direction = RandomDirection(rng).head<2>().normalized();
      s.pixels[i] += LogUniform(rng, 20.0, 500.0) * direction;
      s.description += ", point " + std::to_string(i) + " mis-clicked";
      break;
    }
    case 1:  // at the camera centre, its pixel anywhere
      s.points[i] = CameraCenterInWorld(camera.cam_from_world);
      s.pixels[i] = testing::RandomPixelInImage(rng, camera.size);
      s.description += ", point " + std::to_string(i) + " at the camera centre";
      break;
    case 2: {  // behind the camera, seen where the pinhole formula puts it; the depth drawn
               // before the pixel (testing::DrawVector3 says why)
      const double depth = -Uniform(rng, 2.0, 4.0);
      s.points[i] =
          testing::WorldPointAtPixel(camera, testing::RandomPixelInImage(rng, camera.size), depth);
      s.pixels[i] = ThroughProjection(camera, s.points[i]);
      s.description += ", point " + std::to_string(i) + " behind the camera";
      break;
    }
    default: {  // two pixels swapped
      const int j = UniformInt(rng, 0, n - 1);
      std::swap(s.pixels[i], s.pixels[j]);
      s.description += ", pixels " + std::to_string(i) + " and " + std::to_string(j) + " swapped";
    }
  }
  return s;
}

StressScene WildIntrinsics(std::mt19937_64& rng) {
  testing::RandomCameraOptions options;
  options.max_aspect_ratio = 1.0;
  options.max_principal_offset = 0.0;
  options.max_skew_ratio = 0.0;
  testing::RandomCamera camera = testing::MakeRandomCamera(rng, options);
  Intrinsics& k = camera.intrinsics;
  const double w = camera.size.width;
  const double h = camera.size.height;
  // Field of view log-uniform in 0.01 ... 179 degrees, an extreme in a third of the scenes.
  double fov_deg = LogUniform(rng, 0.01, 179.0);
  if (OneIn(rng, 3)) fov_deg = OneIn(rng, 2) ? 0.01 : 179.0;
  k.fx = k.fy = 0.5 * w / std::tan(0.5 * fov_deg * kPi / 180.0);
  std::string what = ", fov " + Format("%.3g", fov_deg) + " deg";
  if (fov_deg <= 90.0 && OneIn(rng, 2)) {  // principal point 2 to 50 image sizes off the centre
    const double off = LogUniform(rng, 2.0, 50.0);
    const double angle = Uniform(rng, 0.0, 2.0 * kPi);
    k.cx = 0.5 * w + off * w * std::cos(angle);
    k.cy = 0.5 * h + off * h * std::sin(angle);
    what += ", principal point " + Format("%.3g", off) + " image sizes off";
  }
  // Non-square pixels or a strong skew in a third of the scenes, at 6 to 10 points: the screen
  // (square pixels) fails on them, and the outlier search costs more than all the rest above
  // 12 points (LO-RANSAC finding no consensus).
  int n = NumPoints(rng);
  if (OneIn(rng, 3)) {
    n = UniformInt(rng, 6, 10);
    if (OneIn(rng, 2)) {
      k.fy = k.fx * LogUniform(rng, 0.5, 2.0);
      what += ", aspect " + Format("%.2f", k.fy / k.fx);
    } else {
      k.skew = Uniform(rng, -3.0, 3.0) * k.fx;
      what += ", skew " + Format("%.2f", k.skew / k.fx) + " fx";
    }
  }
  StressScene s = GoodScene(rng, camera, n, PixelNoise(rng));
  s.description += what;
  return s;
}

Category CategoryOf(int seed) { return static_cast<Category>(seed % kNumCategories); }

// Scene `seed` of the stress (its category), drawn at seed offset `seed_offset`.
StressScene MakeStressSceneAt(int seed, uint64_t seed_offset) {
  std::mt19937_64 rng(0x5eed0000ULL + static_cast<uint64_t>(seed) + seed_offset);
  switch (CategoryOf(seed)) {
    case kExtremeScale: return ExtremeScale(rng);
    case kLargeOffset: return LargeOffset(rng);
    case kNearDuplicates: return NearDuplicates(rng);
    case kDegenerateShape: return DegenerateShape(rng);
    case kWildPixels: return WildPixels(rng);
    case kPointCount: return PointCount(rng);
    case kOneBadPoint: return OneBadPoint(rng);
    default: return WildIntrinsics(rng);
  }
}

StressScene MakeStressScene(int seed) { return MakeStressSceneAt(seed, testing::SeedOffset()); }

// --- One scene against the contract ----------------------------------------------------------

const char* ReasonName(SceneError::Reason reason) {
  switch (reason) {
    case SceneError::Reason::kTooFewPoints: return "too-few-points";
    case SceneError::Reason::kCollinearPoints: return "collinear";
    case SceneError::Reason::kPlanarUnderdetermined: return "planar-underdetermined";
    case SceneError::Reason::kNonFiniteInput: return "non-finite";
    case SceneError::Reason::kPointsBehindCamera: return "behind";
    case SceneError::Reason::kMirroredWorld: return "mirrored";
    case SceneError::Reason::kDegenerate: return "degenerate";
    case SceneError::Reason::kContaminated: return "contaminated";
    case SceneError::Reason::kInconsistent: return "inconsistent";
    case SceneError::Reason::kAmbiguous: return "ambiguous";
    case SceneError::Reason::kNumerical: return "NUMERICAL";
  }
  return "unknown";
}

struct Outcome {
  std::string result;     // "camera" or the refusal's reason
  std::string model;      // of a camera
  double rms_px = 0.0;    // of a camera
  std::string detail;     // the model, or the refusal's message
  std::string violation;  // empty: the contract held
  double cpu_seconds = 0.0;  // of the fits, on their thread (the wall time depends on the load)
};

double ThreadCpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

// RMS over the kept points of PixelFromWorld(camera, X) - pixel, as a reader of the camera file
// computes it; nullopt (and `violation` set) if a kept point is not in front of the camera.
std::optional<double> RecomputedRms(const Camera& camera, const StressScene& s,
                                    const std::vector<bool>& kept, std::string* violation) {
  double sum_squares = 0.0;
  int count = 0;
  for (size_t i = 0; i < s.points.size(); ++i) {
    if (!kept[i]) continue;
    const std::optional<Eigen::Vector2d> pixel = PixelFromWorld(camera, s.points[i]);
    if (!pixel) {
      *violation = "kept point " + std::to_string(i) + " is not in front of the camera";
      return std::nullopt;
    }
    sum_squares += (*pixel - s.pixels[i]).squaredNorm();
    ++count;
  }
  return std::sqrt(sum_squares / count);
}

// The contract's checks of a returned camera; empty when it holds.
std::string CheckCamera(const FitResult& fit, const StressScene& s) {
  if (!fit.consistency.checked || !fit.consistency.passed) {
    return "returned a camera that did not pass the gate: " + fit.consistency.summary;
  }
  std::vector<bool> kept(s.points.size(), true);
  for (const int i : fit.outliers) {
    if (i < 0 || i >= static_cast<int>(kept.size()) || !kept[i]) {
      return "outlier index " + std::to_string(i) + " is out of range or repeated";
    }
    kept[i] = false;
  }
  if (2 * fit.outliers.size() > s.points.size()) {
    return "left out " + std::to_string(fit.outliers.size()) + " of " +
           std::to_string(s.points.size()) + " points, more than half";
  }
  std::string violation;
  const std::optional<double> rms = RecomputedRms(fit.camera, s, kept, &violation);
  if (!rms) return violation;
  if (!(std::abs(fit.rms_px - *rms) <= kRmsRelative * *rms)) {
    return "printed rms " + Format("%.17g", fit.rms_px) + " px, recomputed from the camera " +
           Format("%.17g", *rms) + " px";
  }
  const Camera read_back = CameraFromJsonText(CameraToJsonText(fit.camera), "stress camera");
  const std::optional<double> file_rms = RecomputedRms(read_back, s, kept, &violation);
  if (!file_rms) return "camera file: " + violation;
  if (*file_rms != *rms) {
    return "rms " + Format("%.17g", *rms) + " px, from the camera file " +
           Format("%.17g", *file_rms) + " px";
  }
  return "";
}

Outcome FitScene(const StressScene& s) {
  Outcome outcome;
  const double start = ThreadCpuSeconds();
  try {
    const FitResult fit = FitCameraAuto(s.points, s.pixels, s.size);
    outcome.result = "camera";
    outcome.model = fit.model;
    outcome.rms_px = fit.rms_px;
    outcome.detail = fit.model + ", rms " + Format("%.3g", fit.rms_px) + " px";
    outcome.violation = CheckCamera(fit, s);
  } catch (const SceneError& e) {
    outcome.result = ReasonName(e.reason());
    outcome.detail = e.what();
    const std::string fix = e.fix();
    if (e.reason() == SceneError::Reason::kNumerical) {
      outcome.violation = "kNumerical: " + outcome.detail;
    } else if (fix.empty() || outcome.detail != e.why() + ". " + fix) {
      outcome.violation = "no fix apart: " + outcome.detail;
    } else if (fix.find("that pixel") != std::string::npos ||
               fix.find("near it") != std::string::npos ||
               fix.find("those points") != std::string::npos) {
      outcome.violation = "a fix that points back into the why: " + fix;
    }
  } catch (const std::exception& e) {
    outcome.result = "OTHER";
    outcome.detail = e.what();
    outcome.violation = std::string("not a SceneError: ") + e.what();
  }
  outcome.cpu_seconds = ThreadCpuSeconds() - start;
  return outcome;
}

// The scene with `points` in place of its own.
StressScene WithPoints(const StressScene& s, const std::vector<Eigen::Vector3d>& points) {
  StressScene moved = s;
  moved.points = points;
  moved.unscaled_points.reset();
  moved.unmoved_points.reset();
  return moved;
}

std::string Differs(const Outcome& moved, const Outcome& before) {
  return moved.result + " (" + moved.detail.substr(0, 200) + "), but before: " + before.result +
         " (" + before.detail.substr(0, 200) + ")";
}

// The contract, and for a scaled or moved scene the comparison with the scene before.
Outcome RunScene(const StressScene& s) {
  Outcome outcome = FitScene(s);
  if (!outcome.violation.empty()) return outcome;
  if (s.unscaled_points) {
    // Times 2^k every coordinate, centroid and RMS distance is exact: the fitter's normalized
    // world, and so every number of the fit, is the same bit for bit.
    const Outcome before = FitScene(WithPoints(s, *s.unscaled_points));
    outcome.cpu_seconds += before.cpu_seconds;
    if (outcome.result != before.result || outcome.model != before.model ||
        outcome.rms_px != before.rms_px) {
      outcome.violation = "scaled by a power of two: " + Differs(outcome, before);
    }
  }
  if (s.unmoved_points && outcome.result != ReasonName(SceneError::Reason::kNonFiniteInput)) {
    const Outcome before = FitScene(WithPoints(s, *s.unmoved_points));
    outcome.cpu_seconds += before.cpu_seconds;
    if (outcome.result != before.result || outcome.model != before.model) {
      outcome.violation = "moved: " + Differs(outcome, before);
    }
  }
  return outcome;
}

// Runs `seeds` on kThreads threads; outcomes in the seeds' order.
std::vector<Outcome> RunScenes(const std::vector<int>& seeds) {
  std::vector<Outcome> outcomes(seeds.size());
  std::atomic<size_t> next{0};
  auto work = [&] {
    for (size_t i = next++; i < seeds.size(); i = next++) {
      outcomes[i] = RunScene(MakeStressScene(seeds[i]));
    }
  };
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) threads.emplace_back(work);
  for (std::thread& t : threads) t.join();
  return outcomes;
}

// Outcomes per category: one row each, one column per outcome seen, and the violations.
std::string Table(const std::vector<int>& seeds, const std::vector<Outcome>& outcomes) {
  std::map<std::string, std::vector<int>> counts;  // outcome -> scenes per category
  std::vector<int> violations(kNumCategories, 0);
  std::vector<double> seconds(kNumCategories, 0.0);
  for (size_t i = 0; i < seeds.size(); ++i) {
    std::vector<int>& row = counts[outcomes[i].result];
    row.resize(kNumCategories, 0);
    ++row[CategoryOf(seeds[i])];
    if (!outcomes[i].violation.empty()) ++violations[CategoryOf(seeds[i])];
    seconds[CategoryOf(seeds[i])] += outcomes[i].cpu_seconds;
  }
  char cell[64];
  std::string table;
  auto add = [&](const char* format, auto value) {
    std::snprintf(cell, sizeof cell, format, value);
    table += cell;
  };
  add("%-17s", "");
  for (const auto& [result, row] : counts) add(" %12s", result.c_str());
  add(" %12s", "VIOLATIONS");
  add(" %9s\n", "CPU s");
  for (int c = 0; c < kNumCategories; ++c) {
    add("%-17s", kCategoryNames[c]);
    for (const auto& [result, row] : counts) add(" %12d", row[c]);
    add(" %12d", violations[c]);
    add(" %9.1f\n", seconds[c]);
  }
  return table;
}

// kNumScenes, or CAMPROJ_STRESS_SCENES when set (a whole number in 1 ... kNumScenes).
int NumScenes() {
  const char* text = std::getenv("CAMPROJ_STRESS_SCENES");
  if (text == nullptr) return kNumScenes;
  char* end = nullptr;
  const long count = std::strtol(text, &end, 10);
  if (end == text || *end != '\0' || count < 1 || count > kNumScenes) {
    ADD_FAILURE() << "CAMPROJ_STRESS_SCENES must be a whole number in 1 ... " << kNumScenes
                  << ", got '" << text << "'";
    return 0;
  }
  return static_cast<int>(count);
}

TEST(FitAutoStress, TwoThousandAdversarialScenesKeepTheContract) {
  std::vector<int> seeds;
  const char* single = std::getenv("CAMPROJ_STRESS_SEED");
  if (single != nullptr) {
    seeds.push_back(std::atoi(single));
  } else {
    for (int seed = 0; seed < NumScenes(); ++seed) seeds.push_back(seed);
  }
  const auto start = std::chrono::steady_clock::now();
  const std::vector<Outcome> outcomes = RunScenes(seeds);
  const std::chrono::duration<double> seconds = std::chrono::steady_clock::now() - start;

  size_t slowest = 0;
  for (size_t i = 0; i < seeds.size(); ++i) {
    if (outcomes[i].cpu_seconds > outcomes[slowest].cpu_seconds) slowest = i;
  }
  std::printf("%zu scenes in %.1f s on %d threads (slowest: seed %d, %.2f s)\n%s", seeds.size(),
              seconds.count(), kThreads, seeds[slowest], outcomes[slowest].cpu_seconds,
              Table(seeds, outcomes).c_str());
  if (single != nullptr) {
    const StressScene s = MakeStressScene(seeds[0]);
    std::printf("seed %d (%s: %s, image %dx%d): %s: %s\n", seeds[0],
                kCategoryNames[CategoryOf(seeds[0])], s.description.c_str(), s.size.width,
                s.size.height, outcomes[0].result.c_str(), outcomes[0].detail.c_str());
  }
  for (size_t i = 0; i < seeds.size(); ++i) {
    if (outcomes[i].violation.empty()) continue;
    ADD_FAILURE() << "seed " << seeds[i] << " (" << kCategoryNames[CategoryOf(seeds[i])] << ": "
                  << MakeStressScene(seeds[i]).description << "): " << outcomes[i].violation
                  << "; rerun with CAMPROJ_STRESS_SEED=" << seeds[i];
  }
}

// Scenes that once broke the contract at another seed offset, at that offset (seeds.h: a seed
// that exposed a bug is kept with its literal seed).
// - 1023 at offset 4096 (wild-intrinsics: N 10, a 0.01 deg view, the principal point 4.49 image
//   sizes off): SQPnP's nearest rotation by FOAM returned matrices up to 0.98 from orthonormal,
//   LM kept the error, and the refit's camera was refused as not a rotation (kNumerical).
// - 1751 at offset 424242 (wild-intrinsics: N 8, a 0.01 deg view, aspect 1.38): SQPnP's search
//   flipped a planar pose seen from behind, and its flip again, without end (a stack overflow).
TEST(FitAutoStress, ScenesThatOnceBrokeTheContract) {
  const std::pair<int, uint64_t> scenes[] = {{1023, 4096}, {1751, 424242}};
  for (const auto& [seed, offset] : scenes) {
    const Outcome outcome = RunScene(MakeStressSceneAt(seed, offset));
    EXPECT_TRUE(outcome.violation.empty())
        << "seed " << seed << " at offset " << offset << ": " << outcome.violation;
  }
}

}  // namespace
}  // namespace camproj

// bench --clicks: the click benchmark of the default fitting path (clicks.h). Single-threaded and
// deterministic: every scene comes from its own seeded std::mt19937_64 and this file's own
// uniform and normal draws (std::*_distribution differ between standard libraries).
#include "clicks.h"

#include <algorithm>
#include <cctype>
#include <functional>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <optional>
#include <random>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

#include "camproj/camera.h"
#include "camproj/camera_file.h"
#include "camproj/fit.h"
#include "camproj/look_at.h"
#include "camproj/model_select.h"
#include "camproj/points_file.h"
#include "camproj/pose.h"
#include "common.h"

#ifndef CAMPROJ_BUILD_TYPE
#define CAMPROJ_BUILD_TYPE "unknown"
#endif
#ifndef CAMPROJ_SOURCE_DIR
#define CAMPROJ_SOURCE_DIR "."
#endif

namespace camproj {
namespace bench {
namespace {

using Clock = std::chrono::steady_clock;
constexpr double kPi = 3.14159265358979323846;

const ImageSize kImageSize{1920, 1080};
constexpr double kClickNoisePx = 0.7;  // Gaussian, per axis, before rounding to a pixel centre
// An answer that puts some unseen model point further than this from where the true projector
// puts it, returned without a refusal, is a silent failure: a visible misalignment on the
// building that the user was not warned about.
constexpr double kSilentFailurePx = 10.0;
// A face seen closer to edge-on than this (cos of the angle between its normal and the direction
// to the projector: 87 deg) shows as a line; its corners are not clicked through it.
constexpr double kMinFacingCos = 0.05;
// The whole building stays this far inside the image, and fills at least kMinImageFill of its
// width or height (a projector is set up to cover the building, not a speck of it).
constexpr double kImageMarginPx = 10.0;
constexpr double kMinImageFill = 0.4;
// Points on a box's surface are not inside it: the interior test shrinks boxes by this (m).
constexpr double kSurfaceEpsilon = 1e-7;
// Two corners closer than this (m) are one corner (boxes side by side or stacked share corners).
constexpr double kSameCornerM = 1e-9;
// Clicked corners whose centred 3D coordinates have smallest / largest singular value below
// this are coplanar: redrawn (a plane cannot determine focal length and principal point).
constexpr double kMinPlanarityRatio = 1e-3;
// Points sampled on the faces: at least this fraction of them on faces of a second normal
// direction (else the points are (nearly) one plane).
constexpr double kMinSecondDirection = 0.1;
constexpr int kGridPerFace = 5;  // unseen points: a 5 x 5 grid on every face facing the projector
// calibrateCamera's start, as mapamok-style tools: a 60 deg horizontal field of view.
constexpr double kOpenCvGuessHfovDeg = 60.0;

// ---------------------------------------------------------------------------------------------
// Random draws

class Rng {
 public:
  explicit Rng(uint64_t seed) : engine_(seed) {}
  // [a, b) from the top 53 bits.
  double Uniform(double a, double b) {
    return a + (b - a) * (static_cast<double>(engine_() >> 11) * 0x1.0p-53);
  }
  // [a, b], a <= b; the modulo bias (< 1e-17) does not matter here.
  int UniformInt(int a, int b) {
    return a + static_cast<int>(engine_() % static_cast<uint64_t>(b - a + 1));
  }
  // Box-Muller; the second value of each pair is dropped to keep the stream simple.
  double Normal() {
    const double u1 = 1.0 - Uniform(0.0, 1.0);  // (0, 1]
    const double u2 = Uniform(0.0, 1.0);
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * kPi * u2);
  }
  // Independent draws (each a fresh call of `draw`) as a vector, drawn last coordinate first.
  // C++ leaves the order of a call's arguments unspecified (GCC goes right to left, clang left
  // to right): Vector3d(draw(), draw(), draw()) would make other scenes with another compiler.
  // Last-first is the order the published tables' scenes were drawn in (GCC).
  template <typename Draw>
  static Eigen::Vector2d Vector2(Draw&& draw) {
    const double y = draw();
    const double x = draw();
    return {x, y};
  }
  template <typename Draw>
  static Eigen::Vector3d Vector3(Draw&& draw) {
    const double z = draw();
    const double y = draw();
    const double x = draw();
    return {x, y, z};
  }
  // The first k entries of a uniformly random permutation of 0..n-1 (partial Fisher-Yates).
  std::vector<int> Choose(int n, int k) {
    std::vector<int> v(n);
    for (int i = 0; i < n; ++i) v[i] = i;
    for (int i = 0; i < k; ++i) std::swap(v[i], v[UniformInt(i, n - 1)]);
    v.resize(k);
    return v;
  }

 private:
  std::mt19937_64 engine_;
};

// SplitMix64's finalizer: independent seeds from small keys.
uint64_t Mix(uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

// ---------------------------------------------------------------------------------------------
// The building: world frame right-handed, metres, z up, ground at z = 0.

struct Box {
  Eigen::Vector3d lo;
  Eigen::Vector3d hi;
};

// Corner `bits` of a box: bit a set -> hi on axis a.
Eigen::Vector3d Corner(const Box& box, int bits) {
  Eigen::Vector3d p;
  for (int a = 0; a < 3; ++a) p(a) = (bits >> a) & 1 ? box.hi(a) : box.lo(a);
  return p;
}

bool InteriorsOverlap(const Box& a, const Box& b) {
  for (int axis = 0; axis < 3; ++axis) {
    if (!(a.lo(axis) < b.hi(axis) - kSurfaceEpsilon && b.lo(axis) < a.hi(axis) - kSurfaceEpsilon)) {
      return false;
    }
  }
  return true;
}

// 1-3 boxes with sides of 0.5-3 m: the first on the ground, each next one stacked on top of an
// earlier box (its footprint inside that box's top) or standing on the ground beside an earlier
// ground box (touching it, overlapping it along the wall by at least 0.25 m).
std::vector<Box> GenerateBuilding(Rng& rng) {
  auto size = [&rng] { return rng.Uniform(0.5, 3.0); };
  std::vector<Box> boxes;
  const Eigen::Vector3d first = Rng::Vector3(size);
  boxes.push_back({Eigen::Vector3d(-0.5 * first.x(), -0.5 * first.y(), 0.0),
                   Eigen::Vector3d(0.5 * first.x(), 0.5 * first.y(), first.z())});
  const int count = rng.UniformInt(1, 3);
  for (int attempt = 0; static_cast<int>(boxes.size()) < count && attempt < 100; ++attempt) {
    Box box;
    if (rng.Uniform(0.0, 1.0) < 0.5) {
      const Box& support = boxes[rng.UniformInt(0, static_cast<int>(boxes.size()) - 1)];
      for (int axis = 0; axis < 2; ++axis) {
        const double width = support.hi(axis) - support.lo(axis);
        const double side = rng.Uniform(0.5, std::max(0.5, std::min(3.0, width)));
        box.lo(axis) =
            rng.Uniform(support.lo(axis), std::max(support.lo(axis), support.hi(axis) - side));
        box.hi(axis) = box.lo(axis) + side;
      }
      box.lo.z() = support.hi.z();
      box.hi.z() = box.lo.z() + size();
    } else {
      std::vector<int> ground;
      for (size_t i = 0; i < boxes.size(); ++i) {
        if (boxes[i].lo.z() == 0.0) ground.push_back(static_cast<int>(i));
      }
      const Box& neighbour = boxes[ground[rng.UniformInt(0, static_cast<int>(ground.size()) - 1)]];
      const int axis = rng.UniformInt(0, 1);
      const int other = 1 - axis;
      const bool positive = rng.Uniform(0.0, 1.0) < 0.5;
      const Eigen::Vector3d s = Rng::Vector3(size);
      if (positive) {
        box.lo(axis) = neighbour.hi(axis);
      } else {
        box.lo(axis) = neighbour.lo(axis) - s(axis);
      }
      box.hi(axis) = box.lo(axis) + s(axis);
      constexpr double kMinOverlap = 0.25;
      box.lo(other) = rng.Uniform(neighbour.lo(other) - s(other) + kMinOverlap,
                                  neighbour.hi(other) - kMinOverlap);
      box.hi(other) = box.lo(other) + s(other);
      box.lo.z() = 0.0;
      box.hi.z() = s.z();
    }
    bool free = true;
    for (const Box& b : boxes) free = free && !InteriorsOverlap(b, box);
    if (free) boxes.push_back(box);
  }
  return boxes;
}

// Whether the segment from p to q passes through the interior of `box` (slab method).
bool SegmentHitsInterior(const Box& box, const Eigen::Vector3d& p, const Eigen::Vector3d& q) {
  const Eigen::Vector3d d = q - p;
  double t_min = 0.0;
  double t_max = 1.0;
  for (int axis = 0; axis < 3; ++axis) {
    const double lo = box.lo(axis) + kSurfaceEpsilon;
    const double hi = box.hi(axis) - kSurfaceEpsilon;
    if (std::abs(d(axis)) < 1e-15) {
      if (p(axis) <= lo || p(axis) >= hi) return false;
      continue;
    }
    double t1 = (lo - p(axis)) / d(axis);
    double t2 = (hi - p(axis)) / d(axis);
    if (t1 > t2) std::swap(t1, t2);
    t_min = std::max(t_min, t1);
    t_max = std::min(t_max, t2);
    if (t_min >= t_max) return false;
  }
  return true;
}

bool Occluded(const std::vector<Box>& boxes, const Eigen::Vector3d& p, const Eigen::Vector3d& eye) {
  for (const Box& box : boxes) {
    if (SegmentHitsInterior(box, p, eye)) return true;
  }
  return false;
}

// A face of a box: outward normal = side * unit(axis).
struct Face {
  int box = 0;
  int axis = 0;
  int side = 1;
};

Eigen::Vector3d Normal(const Face& face) {
  return static_cast<double>(face.side) * Eigen::Vector3d::Unit(face.axis);
}

// A point on the face from (s, t) in [0, 1]^2 over its two other axes.
Eigen::Vector3d PointOnFace(const std::vector<Box>& boxes, const Face& face, double s, double t) {
  const Box& box = boxes[face.box];
  const int a1 = (face.axis + 1) % 3;
  const int a2 = (face.axis + 2) % 3;
  Eigen::Vector3d p;
  p(face.axis) = face.side > 0 ? box.hi(face.axis) : box.lo(face.axis);
  p(a1) = box.lo(a1) + s * (box.hi(a1) - box.lo(a1));
  p(a2) = box.lo(a2) + t * (box.hi(a2) - box.lo(a2));
  return p;
}

double FaceArea(const std::vector<Box>& boxes, const Face& face) {
  const Box& box = boxes[face.box];
  const int a1 = (face.axis + 1) % 3;
  const int a2 = (face.axis + 2) % 3;
  return (box.hi(a1) - box.lo(a1)) * (box.hi(a2) - box.lo(a2));
}

// The face's outward normal points toward the eye, at least kMinFacingCos from edge-on (the
// sign of n . (eye - p) is the same over the whole face; the cosine is taken at `p`).
bool Faces(const Eigen::Vector3d& normal, const Eigen::Vector3d& p, const Eigen::Vector3d& eye) {
  return normal.dot((eye - p).normalized()) > kMinFacingCos;
}

std::vector<Face> FacesTowardEye(const std::vector<Box>& boxes, const Eigen::Vector3d& eye) {
  std::vector<Face> faces;
  for (int b = 0; b < static_cast<int>(boxes.size()); ++b) {
    for (int axis = 0; axis < 3; ++axis) {
      for (int side : {-1, 1}) {
        const Face face{b, axis, side};
        if (Faces(Normal(face), PointOnFace(boxes, face, 0.5, 0.5), eye)) faces.push_back(face);
      }
    }
  }
  return faces;
}

void AddUnique(std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& p) {
  for (const Eigen::Vector3d& q : points) {
    if ((p - q).norm() < kSameCornerM) return;
  }
  points.push_back(p);
}

// ---------------------------------------------------------------------------------------------
// The scene: a building and a projector looking at it.

struct ClickScene {
  std::vector<Box> boxes;
  Camera truth;
  Eigen::Vector3d eye;
  double fovy_deg = 0.0;
  double distance_m = 0.0;  // from the eye to the centre of the building's bounding box
  // Corners a user can click: on a face toward the projector, not hidden by any box.
  std::vector<Eigen::Vector3d> visible_corners;
  // The evaluation points, never given to a fit: every corner of every box and a
  // kGridPerFace^2 grid on every face toward the projector (hidden or not: the projector maps
  // the whole model).
  std::vector<Eigen::Vector3d> unseen_points;
};

bool InsideImage(const Eigen::Vector2d& u, double margin) {
  return u.x() >= margin && u.x() <= kImageSize.width - 1 - margin && u.y() >= margin &&
         u.y() <= kImageSize.height - 1 - margin;
}

// A 1920 x 1080 projector, vertical fov 20-45 deg, square pixels, cx within +-5 % of the image
// centre, cy 0.2-0.5 image heights below it (lens shift), 3-15 m from the building's centre,
// 0.3 m to (top + 5 m) above the ground, at most 60 deg above or below the centre; gaze and roll
// from gluLookAt (up = z) toward the centre, then turned so the centre lands within +-10 % of the
// image centre. Drawn until the whole building is in the image and fills enough of it.
std::optional<Camera> PlaceProjector(const std::vector<Box>& boxes, Rng& rng,
                                     Eigen::Vector3d* eye_out, double* fovy_out) {
  Eigen::Vector3d lo = boxes[0].lo;
  Eigen::Vector3d hi = boxes[0].hi;
  for (const Box& b : boxes) {
    lo = lo.cwiseMin(b.lo);
    hi = hi.cwiseMax(b.hi);
  }
  const Eigen::Vector3d centre = 0.5 * (lo + hi);
  const double width = kImageSize.width;
  const double height = kImageSize.height;
  for (int attempt = 0; attempt < 2000; ++attempt) {
    const double fovy_deg = rng.Uniform(20.0, 45.0);
    const double f = 0.5 * height / std::tan(0.5 * fovy_deg * kPi / 180.0);
    Intrinsics k;
    k.fx = k.fy = f;
    k.cx = 0.5 * (width - 1) + rng.Uniform(-0.05, 0.05) * width;
    k.cy = 0.5 * (height - 1) + rng.Uniform(0.2, 0.5) * height;
    const double distance = rng.Uniform(3.0, 15.0);
    const double azimuth = rng.Uniform(0.0, 2.0 * kPi);
    const double eye_z = rng.Uniform(0.3, hi.z() + 5.0);
    const double dz = eye_z - centre.z();
    if (std::abs(dz) > distance * std::sin(60.0 * kPi / 180.0)) continue;
    const double horizontal = std::sqrt(distance * distance - dz * dz);
    const Eigen::Vector3d eye(centre.x() + horizontal * std::cos(azimuth),
                              centre.y() + horizontal * std::sin(azimuth), eye_z);
    const Eigen::Vector2d target =
        Eigen::Vector2d(0.5 * (width - 1), 0.5 * (height - 1)) +
        Rng::Vector2([&rng] { return rng.Uniform(-0.1, 0.1); }).cwiseProduct(Eigen::Vector2d(width, height));
    const Eigen::Matrix3d look =
        CamFromWorldFromLookAt({eye, centre, Eigen::Vector3d::UnitZ()}).rotation;
    const Eigen::Vector3d ray((target.x() - k.cx) / f, (target.y() - k.cy) / f, 1.0);
    const Eigen::Matrix3d turn =
        Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), ray.normalized())
            .toRotationMatrix();
    Camera camera;
    camera.image_size = kImageSize;
    camera.intrinsics = k;
    camera.cam_from_world = CamFromWorldFromCenter(turn * look, eye);
    camera.z_near = 0.1;
    camera.z_far = 100.0;
    bool inside = true;
    Eigen::Vector2d u_min(width, height);
    Eigen::Vector2d u_max(0.0, 0.0);
    for (const Box& b : boxes) {
      for (int bits = 0; bits < 8 && inside; ++bits) {
        const Eigen::Vector3d p = Corner(b, bits);
        if (!((camera.cam_from_world * p).z() > camera.z_near)) {
          inside = false;
          break;
        }
        const std::optional<Eigen::Vector2d> u = PixelFromWorld(camera, p);
        inside = u && InsideImage(*u, kImageMarginPx);
        if (inside) {
          u_min = u_min.cwiseMin(*u);
          u_max = u_max.cwiseMax(*u);
        }
      }
    }
    if (!inside) continue;
    if (std::max((u_max.x() - u_min.x()) / width, (u_max.y() - u_min.y()) / height) <
        kMinImageFill) {
      continue;
    }
    *eye_out = eye;
    *fovy_out = fovy_deg;
    return camera;
  }
  return std::nullopt;
}

// Buildings and projectors are drawn until at least min_visible_corners corners are visible.
ClickScene GenerateScene(Rng& rng, int min_visible_corners) {
  for (;;) {
    ClickScene scene;
    scene.boxes = GenerateBuilding(rng);
    const std::optional<Camera> camera =
        PlaceProjector(scene.boxes, rng, &scene.eye, &scene.fovy_deg);
    if (!camera) continue;
    scene.truth = *camera;
    Eigen::Vector3d lo = scene.boxes[0].lo;
    Eigen::Vector3d hi = scene.boxes[0].hi;
    for (const Box& b : scene.boxes) {
      lo = lo.cwiseMin(b.lo);
      hi = hi.cwiseMax(b.hi);
    }
    scene.distance_m = (scene.eye - 0.5 * (lo + hi)).norm();
    for (int b = 0; b < static_cast<int>(scene.boxes.size()); ++b) {
      for (int bits = 0; bits < 8; ++bits) {
        const Eigen::Vector3d p = Corner(scene.boxes[b], bits);
        AddUnique(scene.unseen_points, p);
        bool toward = false;
        for (int axis = 0; axis < 3; ++axis) {
          const Face face{b, axis, (bits >> axis) & 1 ? 1 : -1};
          toward = toward || Faces(Normal(face), p, scene.eye);
        }
        if (toward && !Occluded(scene.boxes, p, scene.eye)) AddUnique(scene.visible_corners, p);
      }
    }
    if (static_cast<int>(scene.visible_corners.size()) < min_visible_corners) continue;
    for (const Face& face : FacesTowardEye(scene.boxes, scene.eye)) {
      for (int i = 0; i < kGridPerFace; ++i) {
        for (int j = 0; j < kGridPerFace; ++j) {
          scene.unseen_points.push_back(
              PointOnFace(scene.boxes, face, (i + 0.5) / kGridPerFace, (j + 0.5) / kGridPerFace));
        }
      }
    }
    return scene;
  }
}

// The clicked pixel: the true projection plus Gaussian noise, on a pixel centre in the image.
Eigen::Vector2d Click(const Camera& truth, const Eigen::Vector3d& p, Rng& rng) {
  const Eigen::Vector2d u = *PixelFromWorld(truth, p);
  const double x = std::round(u.x() + kClickNoisePx * rng.Normal());
  const double y = std::round(u.y() + kClickNoisePx * rng.Normal());
  return {std::clamp(x, 0.0, kImageSize.width - 1.0), std::clamp(y, 0.0, kImageSize.height - 1.0)};
}

bool Coplanar(const std::vector<Eigen::Vector3d>& points) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : points) mean += p;
  mean /= static_cast<double>(points.size());
  Eigen::MatrixXd centred(points.size(), 3);
  for (size_t i = 0; i < points.size(); ++i) centred.row(i) = (points[i] - mean).transpose();
  const Eigen::Vector3d s = Eigen::JacobiSVD<Eigen::MatrixXd>(centred).singularValues();
  return !(s(2) > kMinPlanarityRatio * s(0));
}

// ---------------------------------------------------------------------------------------------
// Bands and cases

enum class Variant { kClean, kMisclick, kMirrored, kOutliers };

const char* Name(Variant v) {
  switch (v) {
    case Variant::kClean: return "clean";
    case Variant::kMisclick: return "mis-click";
    case Variant::kMirrored: return "mirrored";
    case Variant::kOutliers: return "outliers";
  }
  return "?";
}

struct Band {
  Variant variant;
  int n_min;
  int n_max;
  double outlier_fraction = 0.0;  // kOutliers only
  std::string name;
};

std::vector<Band> MakeBands() {
  std::vector<Band> bands;
  auto range = [](int a, int b) {
    return a == b ? std::to_string(a) : std::to_string(a) + "-" + std::to_string(b);
  };
  const std::vector<std::pair<int, int>> small = {{6, 6}, {7, 7}, {8, 8}, {9, 10}, {11, 12}};
  for (Variant v : {Variant::kClean, Variant::kMisclick}) {
    for (const auto& [a, b] : small) {
      bands.push_back({v, a, b, 0.0, std::string(Name(v)) + " N=" + range(a, b)});
    }
  }
  for (int n : {6, 8, 12})
    bands.push_back({Variant::kMirrored, n, n, 0.0, "mirrored N=" + range(n, n)});
  for (int n : {60, 100, 300}) {
    for (double fraction : {0.1, 0.3, 0.5}) {
      bands.push_back({Variant::kOutliers, n, n, fraction,
                       "outliers N=" + std::to_string(n) + " " +
                           std::to_string(static_cast<int>(std::lround(100 * fraction))) + "%"});
    }
  }
  return bands;
}

struct Case {
  int band = 0;
  int index = 0;
  uint64_t seed = 0;  // of the geometry and the clean clicks
  int n = 0;
  ClickScene scene;
  std::vector<Eigen::Vector3d> points;  // as given to the fits (mirrored in kMirrored)
  std::vector<Eigen::Vector2d> pixels;
  std::vector<bool> bad;  // a mis-click, or a pixel replaced by a random one
  int mirror_axis = -1;   // kMirrored: the world axis negated in `points`
};

// The geometry and clean clicks depend only on (clicked corners or face samples, N range, scene
// index), so the clean, mis-click and mirrored bands of one N range see the same scenes, and the
// outlier fractions of one N the same points; the perturbation has a stream of its own.
Case MakeCase(const std::vector<Band>& bands, int band_index, int index) {
  const Band& band = bands[band_index];
  Case c;
  c.band = band_index;
  c.index = index;
  const bool faces = band.variant == Variant::kOutliers;
  c.seed = Mix(Mix(Mix(faces ? 2 : 1) ^ static_cast<uint64_t>(1000 * band.n_min + band.n_max)) ^
               static_cast<uint64_t>(index));
  Rng rng(c.seed);
  c.n = rng.UniformInt(band.n_min, band.n_max);
  for (bool done = false; !done;) {
    c.scene = GenerateScene(rng, faces ? 0 : c.n);
    c.points.clear();
    if (faces) {
      // Uniform over the visible area: a face toward the projector by area, a point on it, kept
      // unless another box hides it.
      const std::vector<Face> toward = FacesTowardEye(c.scene.boxes, c.scene.eye);
      if (toward.empty()) continue;
      std::vector<int> per_direction(6, 0);  // points per outward normal (axis, side)
      double total = 0.0;
      for (const Face& f : toward) total += FaceArea(c.scene.boxes, f);
      for (int attempt = 0; attempt < 200 * c.n && static_cast<int>(c.points.size()) < c.n;
           ++attempt) {
        double pick = rng.Uniform(0.0, total);
        size_t f = 0;
        while (f + 1 < toward.size() && pick >= FaceArea(c.scene.boxes, toward[f])) {
          pick -= FaceArea(c.scene.boxes, toward[f]);
          ++f;
        }
        const Eigen::Vector2d on_face = Rng::Vector2([&rng] { return rng.Uniform(0.0, 1.0); });
        const Eigen::Vector3d p = PointOnFace(c.scene.boxes, toward[f], on_face.x(), on_face.y());
        if (!Occluded(c.scene.boxes, p, c.scene.eye)) {
          c.points.push_back(p);
          ++per_direction[2 * toward[f].axis + (toward[f].side > 0 ? 1 : 0)];
        }
      }
      // One view of a plane cannot determine focal length and principal point (the oracle's
      // model): a second face direction must hold kMinSecondDirection of the points.
      std::sort(per_direction.begin(), per_direction.end(), std::greater<int>());
      done = static_cast<int>(c.points.size()) == c.n &&
             per_direction[1] >= kMinSecondDirection * static_cast<double>(c.n);
    } else {
      const int visible = static_cast<int>(c.scene.visible_corners.size());
      for (int attempt = 0; attempt < 50 && !done; ++attempt) {
        c.points.clear();
        for (int i : rng.Choose(visible, c.n)) c.points.push_back(c.scene.visible_corners[i]);
        done = !Coplanar(c.points);
      }
    }
  }
  c.pixels.clear();
  for (const Eigen::Vector3d& p : c.points) c.pixels.push_back(Click(c.scene.truth, p, rng));
  c.bad.assign(c.n, false);

  Rng perturb(Mix(c.seed ^ 0x5eed0fba5eULL) ^ static_cast<uint64_t>(band.variant));
  if (band.variant == Variant::kMisclick) {
    const int i = perturb.UniformInt(0, c.n - 1);
    Eigen::Vector2d moved = c.pixels[i];
    for (int attempt = 0; attempt < 100; ++attempt) {
      const double angle = perturb.Uniform(0.0, 2.0 * kPi);
      const double length = perturb.Uniform(50.0, 200.0);
      moved = c.pixels[i] + length * Eigen::Vector2d(std::cos(angle), std::sin(angle));
      if (InsideImage(moved, 0.0)) break;
    }
    moved = moved.cwiseMax(Eigen::Vector2d::Zero())
                .cwiseMin(Eigen::Vector2d(kImageSize.width - 1, kImageSize.height - 1));
    c.pixels[i] = Eigen::Vector2d(std::round(moved.x()), std::round(moved.y()));
    c.bad[i] = true;
  } else if (band.variant == Variant::kMirrored) {
    c.mirror_axis = perturb.UniformInt(0, 2);
    for (Eigen::Vector3d& p : c.points) p(c.mirror_axis) = -p(c.mirror_axis);
  } else if (band.variant == Variant::kOutliers) {
    const int count = static_cast<int>(std::lround(band.outlier_fraction * c.n));
    for (int i : perturb.Choose(c.n, count)) {
      c.pixels[i] = Eigen::Vector2d(std::round(perturb.Uniform(0.0, kImageSize.width - 1)),
                                    std::round(perturb.Uniform(0.0, kImageSize.height - 1)));
      c.bad[i] = true;
    }
  }
  return c;
}

// ---------------------------------------------------------------------------------------------
// Methods

enum class MethodId { kDefault, kOracle, kOpenCv, kWithModel };
const std::vector<MethodId> kMethodIds = {MethodId::kDefault, MethodId::kOracle, MethodId::kOpenCv,
                                          MethodId::kWithModel};

const char* Name(MethodId m) {
  switch (m) {
    case MethodId::kDefault: return "default";
    case MethodId::kOracle: return "oracle";
    case MethodId::kOpenCv: return "opencv";
    case MethodId::kWithModel: return "default+model";
  }
  return "?";
}

enum class Status { kAnswered, kRefused, kError, kSkipped };

const char* Name(Status s) {
  switch (s) {
    case Status::kAnswered: return "answered";
    case Status::kRefused: return "refused";
    case Status::kError: return "error";
    case Status::kSkipped: return "skipped";
  }
  return "?";
}

std::string ReasonName(SceneError::Reason reason) {
  using R = SceneError::Reason;
  switch (reason) {
    case R::kTooFewPoints: return "too-few-points";
    case R::kCollinearPoints: return "collinear";
    case R::kPlanarUnderdetermined: return "planar-underdetermined";
    case R::kNonFiniteInput: return "non-finite";
    case R::kPointsBehindCamera: return "behind-camera";
    case R::kMirroredWorld: return "mirrored-world";
    case R::kDegenerate: return "degenerate";
    case R::kContaminated: return "contaminated";
    case R::kInconsistent: return "inconsistent";
    case R::kAmbiguous: return "ambiguous";
    case R::kNumerical: return "numerical";
    default: break;  // a reason added after this file
  }
  return "reason-" + std::to_string(static_cast<int>(reason));
}

struct Outcome {
  MethodId method = MethodId::kDefault;
  Status status = Status::kSkipped;
  std::string reason;   // kRefused: ReasonName
  std::string message;  // kRefused / kError: what()
  double time_ms = NAN;
  std::string model;
  std::string outlier_method;
  std::string gate;        // FitResult::consistency: "passed", "failed", "" (not checked)
  std::vector<int> named;  // outliers and left-out points, input indices
  std::optional<Intrinsics> intrinsics;
  double unseen_max_px = NAN;  // kAnswered: over ClickScene::unseen_points; inf if one is behind
  double unseen_mean_px = NAN;
};

// A point of the true world as the clicks give it: mirrored in the mirrored band.
Eigen::Vector3d InGivenWorld(const Case& c, const Eigen::Vector3d& point) {
  Eigen::Vector3d given = point;
  if (c.mirror_axis >= 0) given(c.mirror_axis) = -given(c.mirror_axis);
  return given;
}

// |projection by `camera` - projection by the truth| over the unseen points; the camera was fitted
// in the given (possibly mirrored) world, so the points are mirrored the same way first.
void Score(const Camera& camera, const Case& c, Outcome* outcome) {
  double max = 0.0;
  double sum = 0.0;
  for (const Eigen::Vector3d& x : c.scene.unseen_points) {
    const Eigen::Vector3d given = InGivenWorld(c, x);
    double error = INFINITY;
    try {
      const std::optional<Eigen::Vector2d> u = PixelFromWorld(camera, given);
      if (u && u->allFinite()) error = (*u - *PixelFromWorld(c.scene.truth, x)).norm();
    } catch (const std::exception&) {
      // An invalid camera (e.g. fx <= 0 from OpenCV): infinitely wrong.
    }
    if (!(error == error)) error = INFINITY;
    max = std::max(max, error);
    sum += error;
  }
  outcome->unseen_max_px = max;
  outcome->unseen_mean_px = sum / static_cast<double>(c.scene.unseen_points.size());
}

void RecordFit(const FitResult& fit, const Case& c, Outcome* outcome) {
  outcome->status = Status::kAnswered;
  outcome->model = fit.model;
  outcome->outlier_method = fit.outlier_method;
  outcome->gate = fit.consistency.checked ? (fit.consistency.passed ? "passed" : "failed") : "";
  outcome->named = fit.outliers;
  for (const LeftOutPoint& p : fit.left_out) outcome->named.push_back(p.index);
  std::sort(outcome->named.begin(), outcome->named.end());
  outcome->named.erase(std::unique(outcome->named.begin(), outcome->named.end()),
                       outcome->named.end());
  outcome->intrinsics = fit.camera.intrinsics;
  Score(fit.camera, c, outcome);
}

double MillisecondsBetween(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

// As bench.cc's cv-calib method: calibrateCamera on the one view from a guess (60 deg horizontal
// field of view, principal point at the image centre), aspect fixed at 1, no distortion.
Camera CvCalibrate(const std::vector<Eigen::Vector3d>& points,
                   const std::vector<Eigen::Vector2d>& pixels) {
  std::vector<std::vector<cv::Point3f>> object(1);
  std::vector<std::vector<cv::Point2f>> image(1);
  for (size_t i = 0; i < points.size(); ++i) {
    object[0].emplace_back(static_cast<float>(points[i].x()), static_cast<float>(points[i].y()),
                           static_cast<float>(points[i].z()));
    image[0].emplace_back(static_cast<float>(pixels[i].x()), static_cast<float>(pixels[i].y()));
  }
  const double focal = 0.5 * kImageSize.width / std::tan(0.5 * kOpenCvGuessHfovDeg * kPi / 180.0);
  cv::Mat k = (cv::Mat_<double>(3, 3) << focal, 0, 0.5 * (kImageSize.width - 1), 0, focal,
               0.5 * (kImageSize.height - 1), 0, 0, 1);
  cv::Mat distortion = cv::Mat::zeros(5, 1, CV_64F);
  std::vector<cv::Mat> rvecs;
  std::vector<cv::Mat> tvecs;
  const int flags = cv::CALIB_USE_INTRINSIC_GUESS | cv::CALIB_FIX_ASPECT_RATIO |
                    cv::CALIB_ZERO_TANGENT_DIST | cv::CALIB_FIX_K1 | cv::CALIB_FIX_K2 |
                    cv::CALIB_FIX_K3;
  cv::calibrateCamera(object, image, cv::Size(kImageSize.width, kImageSize.height), k, distortion,
                      rvecs, tvecs, flags);
  Camera camera;
  camera.image_size = kImageSize;
  camera.intrinsics = IntrinsicsFromCv(k);
  camera.cam_from_world = RigidFromCv(rvecs.at(0), tvecs.at(0));
  return camera;
}

// The points a refusal tells the user to fix first ("Fix or drop point 5 (98 px from where the
// camera puts it)"), as input indices; FitCameraAuto names unnamed points "point <row>".
std::vector<int> NamedByRefusal(const std::string& message) {
  std::vector<int> named;
  static const std::regex kFix("Fix or drop point ([0-9]+) \\(");
  for (auto it = std::sregex_iterator(message.begin(), message.end(), kFix);
       it != std::sregex_iterator(); ++it) {
    named.push_back(std::stoi((*it)[1].str()) - 1);
  }
  std::sort(named.begin(), named.end());
  named.erase(std::unique(named.begin(), named.end()), named.end());
  return named;
}

// The corners of every box of the building, in the world the clicks are given in: what a user
// who maps onto a model has (its vertices), for AutoFitOptions::object_points_in_world.
std::vector<Eigen::Vector3d> ModelVertices(const Case& c) {
  std::vector<Eigen::Vector3d> vertices;
  for (const Box& box : c.scene.boxes) {
    for (int bits = 0; bits < 8; ++bits) {
      vertices.push_back(InGivenWorld(c, Corner(box, bits)));
    }
  }
  return vertices;
}

// One method on one case; the clock covers the library call only. Nothing but a refusal
// (SceneError) is expected from camproj; anything else is recorded as an error, never rethrown.
Outcome Run(MethodId method, const Case& c, const Band& band) {
  Outcome outcome;
  outcome.method = method;
  std::vector<Eigen::Vector3d> points = c.points;
  std::vector<Eigen::Vector2d> pixels = c.pixels;
  if (method == MethodId::kOracle) {
    if (band.variant == Variant::kMirrored) return outcome;  // no true model in a mirrored world
    points.clear();
    pixels.clear();
    for (int i = 0; i < c.n; ++i) {
      if (c.bad[i]) continue;
      points.push_back(c.points[i]);
      pixels.push_back(c.pixels[i]);
    }
  }
  Clock::time_point start = Clock::now();
  try {
    if (method == MethodId::kDefault) {
      start = Clock::now();
      const FitResult fit = FitCameraAuto(points, pixels, kImageSize, AutoFitOptions{});
      outcome.time_ms = MillisecondsBetween(start, Clock::now());
      RecordFit(fit, c, &outcome);
    } else if (method == MethodId::kWithModel) {
      AutoFitOptions options;
      options.object_points_in_world = ModelVertices(c);
      start = Clock::now();
      const FitResult fit = FitCameraAuto(points, pixels, kImageSize, options);
      outcome.time_ms = MillisecondsBetween(start, Clock::now());
      RecordFit(fit, c, &outcome);
    } else if (method == MethodId::kOracle) {
      FitOptions options;  // focal free
      options.aspect = ParameterMode::Default();
      options.principal_point = ParameterMode::Free();
      options.compute_uncertainty = false;
      start = Clock::now();
      const FitResult fit = FitCamera(points, pixels, kImageSize, options);
      outcome.time_ms = MillisecondsBetween(start, Clock::now());
      RecordFit(fit, c, &outcome);
    } else {
      start = Clock::now();
      const Camera camera = CvCalibrate(points, pixels);
      outcome.time_ms = MillisecondsBetween(start, Clock::now());
      outcome.status = Status::kAnswered;
      outcome.model = "pose+focal+principal-point";
      outcome.intrinsics = camera.intrinsics;
      Score(camera, c, &outcome);
    }
  } catch (const SceneError& e) {
    outcome.time_ms = MillisecondsBetween(start, Clock::now());
    outcome.status = Status::kRefused;
    outcome.reason = ReasonName(e.reason());
    outcome.message = e.what();
    outcome.named = NamedByRefusal(outcome.message);
  } catch (const std::exception& e) {
    outcome.time_ms = MillisecondsBetween(start, Clock::now());
    outcome.status = Status::kError;
    outcome.message = e.what();
  } catch (...) {
    outcome.time_ms = MillisecondsBetween(start, Clock::now());
    outcome.status = Status::kError;
    outcome.message = "unknown exception (not a std::exception)";
  }
  return outcome;
}

// A silent failure: an answer more than kSilentFailurePx off somewhere on the model; in a
// mirrored world every answer (no proper camera is right there).
bool Silent(const Outcome& o, const Band& band) {
  if (o.status != Status::kAnswered) return false;
  return band.variant == Variant::kMirrored || !(o.unseen_max_px <= kSilentFailurePx);
}

// ---------------------------------------------------------------------------------------------
// Statistics per band

// A message with its numbers replaced by '#', so equal causes count together.
std::string MessageKind(const std::string& message) {
  static const std::regex number(R"(-?[0-9]+(\.[0-9]+)?([eE][-+]?[0-9]+)?)");
  std::string text = std::regex_replace(message, number, "#").substr(0, 140);
  std::replace(text.begin(), text.end(), '|', '/');
  std::replace(text.begin(), text.end(), '\n', ' ');
  return text;
}

struct BandStats {
  int scenes = 0;
  int answered = 0;
  int refused = 0;
  int errors = 0;
  int silent = 0;
  std::map<std::string, int> refusals;          // reason -> count
  std::map<std::string, int> refusal_messages;  // "reason: message kind" -> count
  std::map<std::string, int> error_messages;    // "method: message kind" -> count
  std::vector<double> default_error;            // answered scenes
  std::vector<double> oracle_error_same;        // scenes the default answered too
  int bad_total = 0;                            // mis-clicks / replaced pixels over all scenes
  int bad_named = 0;                            // of those, named by the default
  int scenes_with_bad = 0;
  int scenes_bad_named = 0;  // scenes whose every bad point was named
  int good_named = 0;        // good points named, summed over scenes
  int scenes_good_named = 0;
  std::vector<double> default_time_ms;  // every call, refusals included
  std::vector<double> oracle_time_ms;
  int oracle_runs = 0;
  int oracle_answered = 0;
  int oracle_refused = 0;
  int oracle_over = 0;               // answered, unseen error > kSilentFailurePx
  std::vector<double> oracle_error;  // every oracle answer
  int opencv_answered = 0;
  int opencv_failed = 0;  // exception from OpenCV
  int opencv_over = 0;
  std::vector<double> opencv_error;
  std::vector<double> opencv_time_ms;
  std::map<std::string, int> models;  // the default's chosen models
  int with_model_answered = 0;        // default+model
  int with_model_silent = 0;
  std::vector<double> with_model_error;
};

void Accumulate(const Band& band, const Case& c, const std::vector<Outcome>& outcomes,
                BandStats* s) {
  const Outcome& def = outcomes[0];
  const Outcome& oracle = outcomes[1];
  const Outcome& opencv = outcomes[2];
  const Outcome& with_model = outcomes[3];
  ++s->scenes;
  if (with_model.status == Status::kAnswered) {
    ++s->with_model_answered;
    s->with_model_error.push_back(with_model.unseen_max_px);
    if (Silent(with_model, band)) ++s->with_model_silent;
  } else if (with_model.status == Status::kError) {
    ++s->error_messages["default+model: " + MessageKind(with_model.message)];
  }
  const int bad = static_cast<int>(std::count(c.bad.begin(), c.bad.end(), true));
  s->bad_total += bad;
  if (bad > 0) ++s->scenes_with_bad;
  s->default_time_ms.push_back(def.time_ms);
  int bad_named = 0;
  int good_named = 0;
  for (int i : def.named) {
    if (i >= 0 && i < c.n && c.bad[i]) {
      ++bad_named;
    } else {
      ++good_named;
    }
  }
  s->bad_named += bad_named;
  if (bad > 0 && bad_named == bad) ++s->scenes_bad_named;
  s->good_named += good_named;
  if (good_named > 0) ++s->scenes_good_named;
  if (def.status == Status::kAnswered) {
    ++s->answered;
    ++s->models[def.model];
    s->default_error.push_back(def.unseen_max_px);
    if (Silent(def, band)) ++s->silent;
    if (oracle.status == Status::kAnswered) s->oracle_error_same.push_back(oracle.unseen_max_px);
  } else if (def.status == Status::kRefused) {
    ++s->refused;
    ++s->refusals[def.reason];
    ++s->refusal_messages[def.reason + ": " + MessageKind(def.message)];
  } else {
    ++s->errors;
    ++s->error_messages["default: " + MessageKind(def.message)];
  }
  if (oracle.status != Status::kSkipped) {
    ++s->oracle_runs;
    s->oracle_time_ms.push_back(oracle.time_ms);
    if (oracle.status == Status::kAnswered) {
      ++s->oracle_answered;
      s->oracle_error.push_back(oracle.unseen_max_px);
      if (!(oracle.unseen_max_px <= kSilentFailurePx)) ++s->oracle_over;
    } else if (oracle.status == Status::kRefused) {
      ++s->oracle_refused;
    } else {
      ++s->error_messages["oracle: " + MessageKind(oracle.message)];
    }
  }
  s->opencv_time_ms.push_back(opencv.time_ms);
  if (opencv.status == Status::kAnswered) {
    ++s->opencv_answered;
    s->opencv_error.push_back(opencv.unseen_max_px);
    if (Silent(opencv, band)) ++s->opencv_over;
  } else {
    ++s->opencv_failed;
  }
}

// ---------------------------------------------------------------------------------------------
// Output

// Pixel errors: 3 significant digits, no exponent below 1e5.
std::string FormatPx(double v) {
  if (std::isnan(v) || std::isinf(v)) return Format(v);
  if (std::abs(v) >= 100.0 && std::abs(v) < 1e5) return Format(v, "%.0f");
  return Format(v, "%.3g");
}

std::string FormatMs(double ms) {
  if (std::isnan(ms)) return "-";
  return ms < 1.0 ? Format(1000.0 * ms, "%.3g") + " µs" : Format(ms, "%.3g") + " ms";
}

std::string Fraction(int a, int b) { return std::to_string(a) + "/" + std::to_string(b); }

std::string UtcNow() {
  const std::time_t now = std::time(nullptr);
  char buffer[32];
  std::strftime(buffer, sizeof buffer, "%Y-%m-%d %H:%M:%S UTC", std::gmtime(&now));
  return buffer;
}

std::string RefusalSummary(const BandStats& s) {
  std::string text = std::to_string(s.refused);
  if (s.refusals.empty()) return text;
  text += " (";
  bool first = true;
  for (const auto& [reason, count] : s.refusals) {
    text += (first ? "" : ", ") + reason + " " + std::to_string(count);
    first = false;
  }
  return text + ")";
}

std::string BadNamed(const Band& band, const BandStats& s) {
  if (band.variant == Variant::kMisclick) return Fraction(s.scenes_bad_named, s.scenes_with_bad);
  if (band.variant == Variant::kOutliers) return Fraction(s.bad_named, s.bad_total);
  return "-";
}

std::string GoodNamed(const BandStats& s) {
  if (s.good_named == 0) return "0";
  return std::to_string(s.good_named) + " (" + std::to_string(s.scenes_good_named) + " scenes)";
}

double Ratio(double a, double b) { return b > 0.0 ? a / b : NAN; }

// The ratio, and on how many of the default's answers when the oracle missed some.
std::string RatioCell(double ratio, const BandStats& s) {
  std::string text = Format(ratio, "%.2f");
  if (s.oracle_error_same.size() < s.default_error.size()) {
    text += " (on " + std::to_string(s.oracle_error_same.size()) + " of " +
            std::to_string(s.default_error.size()) + ")";
  }
  return text;
}

std::string MainTable(const std::vector<Band>& bands, const std::vector<BandStats>& stats) {
  std::ostringstream out;
  out << "| band | scenes | answered | refused (by reason) | errors | default p50 px | default p90 "
         "px "
         "| oracle p50 px | oracle p90 px | p90 ratio | bad named | good named | SILENT | "
         "t default | t oracle |\n"
         "|---|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  BandStats total;
  for (size_t b = 0; b < bands.size(); ++b) {
    const BandStats& s = stats[b];
    const bool mirrored = bands[b].variant == Variant::kMirrored;
    const double d90 = Percentile90(s.default_error);
    const double o90 = Percentile90(s.oracle_error_same);
    out << "| " << bands[b].name << " | " << s.scenes << " | " << s.answered << " | "
        << RefusalSummary(s) << " | " << s.errors << " | " << FormatPx(Median(s.default_error))
        << " | " << FormatPx(d90) << " | "
        << (mirrored ? "-" : FormatPx(Median(s.oracle_error_same))) << " | "
        << (mirrored ? "-" : FormatPx(o90)) << " | "
        << (mirrored ? "-" : RatioCell(Ratio(d90, o90), s)) << " | " << BadNamed(bands[b], s)
        << " | " << GoodNamed(s) << " | **" << s.silent << "** | "
        << FormatMs(Median(s.default_time_ms)) << " | "
        << (mirrored ? "-" : FormatMs(Median(s.oracle_time_ms))) << " |\n";
    total.scenes += s.scenes;
    total.answered += s.answered;
    total.refused += s.refused;
    total.errors += s.errors;
    total.silent += s.silent;
    for (const auto& [reason, count] : s.refusals) total.refusals[reason] += count;
  }
  out << "| **all** | " << total.scenes << " | " << total.answered << " | " << RefusalSummary(total)
      << " | " << total.errors << " | | | | | | | | **" << total.silent << "** | | |\n";
  return out.str();
}

std::string ContextTable(const std::vector<Band>& bands, const std::vector<BandStats>& stats) {
  std::ostringstream out;
  out << "| band | oracle answered | oracle refused | oracle p50 px (all) | oracle p90 px (all) | "
         "oracle > 10 px | opencv answered | opencv p50 px | opencv p90 px | opencv silent | "
         "t opencv | with model answered | with model p90 px | with model SILENT | default models |\n"
         "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|\n";
  for (size_t b = 0; b < bands.size(); ++b) {
    const BandStats& s = stats[b];
    const bool mirrored = bands[b].variant == Variant::kMirrored;
    std::string models;
    for (const auto& [model, count] : s.models) {
      models += (models.empty() ? "" : ", ") + model + " " + std::to_string(count);
    }
    out << "| " << bands[b].name << " | "
        << (mirrored ? "-" : Fraction(s.oracle_answered, s.oracle_runs)) << " | "
        << (mirrored ? "-" : std::to_string(s.oracle_refused)) << " | "
        << (mirrored ? "-" : FormatPx(Median(s.oracle_error))) << " | "
        << (mirrored ? "-" : FormatPx(Percentile90(s.oracle_error))) << " | "
        << (mirrored ? "-" : std::to_string(s.oracle_over)) << " | "
        << Fraction(s.opencv_answered, s.scenes) << " | " << FormatPx(Median(s.opencv_error))
        << " | " << FormatPx(Percentile90(s.opencv_error)) << " | " << s.opencv_over << " | "
        << FormatMs(Median(s.opencv_time_ms)) << " | " << s.with_model_answered << " | "
        << FormatPx(Percentile90(s.with_model_error)) << " | **" << s.with_model_silent << "** | "
        << (models.empty() ? "-" : models) << " |\n";
  }
  return out.str();
}

std::string Csv(const std::string& text) {
  if (text.find_first_of(",\"\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (char ch : text) {
    if (ch == '"') quoted += '"';
    quoted += ch == '\n' ? ' ' : ch;
  }
  return quoted + "\"";
}

void WriteCsvRow(std::ostream& out, const Band& band, const Case& c, const Outcome& o) {
  auto num = [](double v) { return std::isnan(v) ? std::string() : Format(v, "%.6g"); };
  int bad_named = 0;
  int good_named = 0;
  std::string named;
  for (int i : o.named) {
    (i >= 0 && i < c.n && c.bad[i] ? bad_named : good_named) += 1;
    named += (named.empty() ? "" : ";") + std::to_string(i);
  }
  std::string bad;
  for (int i = 0; i < c.n; ++i) {
    if (c.bad[i]) bad += (bad.empty() ? "" : ";") + std::to_string(i);
  }
  const Intrinsics& t = c.scene.truth.intrinsics;
  out << Csv(band.name) << ',' << Name(band.variant) << ',' << c.n << ',' << band.outlier_fraction
      << ',' << c.index << ',' << c.seed << ',' << Name(o.method) << ',' << Name(o.status) << ','
      << o.reason << ',' << Csv(o.model) << ',' << o.outlier_method << ',' << o.gate << ','
      << num(o.time_ms) << ',' << num(o.unseen_max_px) << ',' << num(o.unseen_mean_px) << ','
      << (Silent(o, band) ? 1 : 0) << ',' << bad << ',' << named << ',' << bad_named << ','
      << good_named << ',' << Format(c.scene.fovy_deg, "%.4g") << ',' << num(t.fx) << ','
      << num(t.cx) << ',' << num(t.cy) << ',' << (o.intrinsics ? num(o.intrinsics->fx) : "") << ','
      << (o.intrinsics ? num(o.intrinsics->cx) : "") << ','
      << (o.intrinsics ? num(o.intrinsics->cy) : "") << ',' << c.scene.boxes.size() << ','
      << Format(c.scene.distance_m, "%.4g") << ',' << c.scene.visible_corners.size() << ','
      << c.scene.unseen_points.size() << ',' << c.mirror_axis << ',' << Csv(o.message) << '\n';
}

const char* kCsvHeader =
    "band,variant,n,outlier_fraction,scene,seed,method,status,reason,model,outlier_method,gate,"
    "time_ms,unseen_max_px,unseen_mean_px,silent,bad,named,bad_named,good_named,true_fovy_deg,"
    "true_fx,true_cx,true_cy,fx,cx,cy,boxes,distance_m,visible_corners,unseen_points,mirror_axis,"
    "message\n";

const char* kLegend = R"md(## Scenes

Projection-mapping scenes as a user clicks them (apps/bench/clicks.cc). World: right-handed,
metres, **z up**, ground z = 0. A building of 1-3 axis-aligned boxes, sides 0.5-3 m: the first on
the ground, each next one either stacked on an earlier box (footprint inside its top) or on the
ground beside an earlier ground box (touching it). A 1920x1080 projector: vertical fov 20-45°,
square pixels, no skew or distortion, cx = centre ± 5 % of the width, cy = centre + 0.2-0.5 image
heights (lens shift: the principal point between the middle and the bottom edge and beyond), 3-15 m
from the building's centre, 0.3 m to (top + 5 m) above the ground, at most 60° above or below the
centre, gluLookAt (up = z) toward the centre, turned so the centre lands within ±10 % of the image
centre; drawn until every box corner is in front, ≥ 10 px inside the image, and the building spans
≥ 40 % of the image width or height.

Clicks: the visible box corners (a corner is visible when one of its three faces has its outward
normal toward the projector, more than 3° from edge-on, and the segment from the corner to the
projector passes through no box's interior; corners shared by two boxes count once), N of them at
random, redrawn when coplanar; pixel = true projection + Gaussian noise σ = 0.7 px per axis,
rounded to a pixel centre.

Bands: **clean**; **mis-click**: one click moved 50-200 px in a random direction (kept inside
the image); **mirrored**: the clean scene's clicks with one world axis (random: x, y or z) negated
in the 3D points, the pixels those of the real scene; **outliers**: N points uniform over the
visible area of the faces toward the projector (redrawn unless ≥ 10 % of them lie on faces of a
second normal direction: no flat facades), σ = 0.7 px, rounded, then the given fraction of them
replaced by uniformly random pixels. Bands with the same N range share their scenes (clean,
mis-click and mirrored N=6 and N=8; every outlier fraction of one N): the same index is the same
building, projector and click noise.

Unseen model points (never given to a fit): every corner of every box (hidden ones too) and a 5x5
grid on every face toward the projector. **Unseen error** of a camera = max over those points of
|its projection − the true projector's| in px (inf if a point falls behind it); for the mirrored
band the points are mirrored before the returned camera projects them (the misalignment the user
would see).

## Methods

- **default**: `FitCameraAuto(points, pixels, {1920, 1080}, AutoFitOptions{})`, what
  `camproj fit POINTS.csv --image-size 1920x1080` runs. A returned FitResult is an answer; a
  camproj::SceneError a refusal (its reason); any other exception an error.
- **oracle**: `FitCamera` with the true model (pose + focal + principal point, square pixels, no
  skew or distortion; compute_uncertainty = false) on the good clicks only (mis-click or outliers
  removed); none for the mirrored band.
- **opencv**: `cv::calibrateCamera` on the same clicks as the default, from a 60° horizontal-fov
  guess with the principal point at the centre; CALIB_USE_INTRINSIC_GUESS | CALIB_FIX_ASPECT_RATIO
  | CALIB_ZERO_TANGENT_DIST | CALIB_FIX_K1..K3 (what mapamok-style tools run).
- **default+model**: the default with the building's box corners (the model's vertices, in the
  given world) as `AutoFitOptions::object_points_in_world` (`camproj fit --object-points`): the
  camera must also be determined there.

## Columns

- **band**: variant and N (a range: N drawn uniformly in it per scene).
- **answered / refused / errors**: the default's answers, SceneError refusals (by reason), other
  exceptions (their messages in the sections after the tables).
- **default p50 / p90 px**: median and 90th percentile (nearest rank) over the default's answers of
  the unseen error. **oracle p50 / p90 px**: the same for the oracle on the scenes the default
  answered (where the oracle answered too). **p90 ratio** = default p90 / oracle p90, "(on k of
  m)" when the oracle answered only k of the default's m answered scenes (at mis-click N=6 it has
  5 points for 9 unknowns and mostly refuses).
- **bad named**: mis-click band: scenes whose mis-click the default named (FitResult::outliers or
  left_out, or a refusal's "Fix or drop point K" when the other points do not determine the
  camera) / scenes; outlier bands: replaced points named / replaced points, over all scenes.
  **good named**: good points the default named, summed over its answers and refusals (and in how
  many scenes).
- **SILENT**: silent failures = answers with unseen error > 10 px; in the mirrored band every
  answer (no proper camera is right in a mirrored world).
- **t default / t oracle**: median wall time per call (refusals included), one core; other work
  on the machine inflates them (load average in the header).
- Second table: the oracle over all scenes of the band (answers, refusals, unseen error, answers
  more than 10 px off), OpenCV's answers and errors (its exceptions count as not answered; its
  'silent' uses the same rule), default+model's answers, p90 unseen error and silent failures, and
  the models the default chose.
)md";

// A scene as files a user can fit by hand: the clicks as given (mirrored world included), the
// true camera, and the unseen points with their true pixels (in the given world).
void DumpCase(const std::string& dir, const Band& band, const Case& c) {
  std::string stem = band.name + "-" + std::to_string(c.index);
  for (char& ch : stem) {
    if (!std::isalnum(static_cast<unsigned char>(ch)) && ch != '-') ch = '_';
  }
  const std::filesystem::path base = std::filesystem::path(dir) / stem;
  auto write = [](const std::filesystem::path& path, const std::string& text) {
    std::ofstream out(path);
    out << text;
    if (!out) throw std::runtime_error("cannot write " + path.string());
  };
  Correspondences clicks;
  clicks.points_in_world = c.points;
  clicks.pixels = c.pixels;
  for (int i = 0; i < c.n; ++i) clicks.ids.push_back(std::to_string(i + 1));
  write(base.string() + ".csv", CorrespondencesToCsvText(clicks));
  write(base.string() + "-truth.json", CameraToJsonText(c.scene.truth));
  Correspondences unseen;
  for (const Eigen::Vector3d& x : c.scene.unseen_points) {
    unseen.points_in_world.push_back(InGivenWorld(c, x));
    unseen.pixels.push_back(*PixelFromWorld(c.scene.truth, x));
    unseen.ids.push_back(std::to_string(unseen.ids.size() + 1));
  }
  write(base.string() + "-unseen.csv", CorrespondencesToCsvText(unseen));
}

// ---------------------------------------------------------------------------------------------
// Options and main

struct ClicksOptions {
  bool quick = false;
  std::string out_dir = "clicks-results";
  std::string dump_dir;  // non-empty: each silent failure's scene is written there
  int scenes = 0;  // per band; 0: 100, or 5 with --quick
  // The first scene index: the rules of the default path were measured and chosen on scenes
  // 0-99 (the development set); scenes from 100 on are held out to check that they generalize.
  int first_scene = 0;
  std::string command;
};

const char* kClicksUsage =
    "bench --clicks: the click benchmark of the default fitting path.\n"
    "\n"
    "Usage: bench --clicks [--quick] [--out DIR] [--scenes N] [--first-scene K] [--dump DIR]\n"
    "\n"
    "Fits seeded projection-mapping scenes (1-3 boxes, a 1920x1080 projector with lens shift,\n"
    "6-12 clicked corners rounded to pixels, sigma 0.7 px; a mis-click; a mirrored world model;\n"
    "60-300 points with 10-50 % outliers) with FitCameraAuto's defaults (what `camproj fit` "
    "runs),\n"
    "the true model on the good clicks (oracle) and OpenCV's calibrateCamera, and reports per "
    "band\n"
    "the answers, refusals, error on unseen model points, named outliers and silent failures\n"
    "(answers more than 10 px off somewhere on the model). Single-threaded, deterministic.\n"
    "\n"
    "  --quick      5 scenes per band (a smoke test)\n"
    "  --out DIR    output directory (default clicks-results): clicks.md, clicks.csv\n"
    "  --scenes N   scenes per band (default 100; 5 with --quick)\n"
    "  --first-scene K\n"
    "               scenes K to K+N-1 (default 0). The default path's rules were chosen on\n"
    "               scenes 0-99; --first-scene 100 measures held-out scenes\n"
    "  --dump DIR   write each silent failure of the default as DIR/<band>-<scene>.csv (the\n"
    "               clicks, for `camproj fit`), -truth.json and -unseen.csv (X,Y,Z,u,v of the\n"
    "               unseen points in the given world, as the true projector sees them)\n"
    "\n"
    "Exit codes: 0 ok; 1 usage, or with --quick: a silent failure of the default path or an\n"
    "exception other than SceneError from a camproj fit; 2 error.\n"
    "\n"
    "Example:\n"
    "  bench --clicks --out docs/bench/clicks     (what scripts/bench_clicks.sh runs)\n";

// Every band's scenes, every method: the statistics per band, the CSV's rows, and (with
// --dump) the default's silent failures as files.
std::vector<BandStats> RunBands(const ClicksOptions& options, const std::vector<Band>& bands,
                                int scenes, std::ostringstream* csv) {
  std::vector<BandStats> stats(bands.size());
  for (size_t b = 0; b < bands.size(); ++b) {
    const Clock::time_point band_begin = Clock::now();
    for (int index = options.first_scene; index < options.first_scene + scenes; ++index) {
      const Case c = MakeCase(bands, static_cast<int>(b), index);
      std::vector<Outcome> outcomes;
      for (MethodId m : kMethodIds) outcomes.push_back(Run(m, c, bands[b]));
      Accumulate(bands[b], c, outcomes, &stats[b]);
      if (!options.dump_dir.empty() && Silent(outcomes[0], bands[b])) {
        std::filesystem::create_directories(options.dump_dir);
        DumpCase(options.dump_dir, bands[b], c);
      }
      for (const Outcome& o : outcomes) {
        if (o.status != Status::kSkipped) WriteCsvRow(*csv, bands[b], c, o);
      }
    }
    std::cerr << "bench --clicks: " << bands[b].name << ": " << scenes << " scenes, "
              << Format(MillisecondsBetween(band_begin, Clock::now()) / 1000.0, "%.1f") << " s\n";
  }
  return stats;
}

// The section of `title` listing each band's messages in BandStats' `messages` member with their
// counts; nothing where no band has one.
std::string MessagesSection(const std::string& title_and_header, const std::vector<Band>& bands,
                            const std::vector<BandStats>& stats,
                            std::map<std::string, int> BandStats::*messages) {
  std::ostringstream out;
  bool any = false;
  for (const BandStats& s : stats) any = any || !(s.*messages).empty();
  if (!any) return "";
  out << title_and_header;
  for (size_t b = 0; b < bands.size(); ++b) {
    for (const auto& [message, count] : stats[b].*messages) {
      out << "| " << bands[b].name << " | " << count << " | " << message << " |\n";
    }
  }
  out << '\n';
  return out.str();
}

// What the run's clicks.md says besides its tables: the command, the scenes and the machine.
struct RunFacts {
  int scenes = 0;
  double seconds = 0.0;
  std::string load_before;
  int silent = 0;
};

std::string ReportText(const ClicksOptions& options, const std::vector<Band>& bands,
                       const std::vector<BandStats>& stats, const RunFacts& run,
                       const std::string& main_table, const std::string& context_table) {
  std::ostringstream out;
  out << "# Click benchmark of the default fitting path\n\n"
      << "Generated by `" << options.command << "` (apps/bench/clicks.cc; "
      << "`bash scripts/bench_clicks.sh` reruns it). Do not edit by hand.\n\n"
      << "| | |\n|---|---|\n"
      << "| command | `" << options.command << "` |\n"
      << "| git | " << GitDescription() << " |\n"
      << "| date | " << UtcNow() << " |\n"
      << "| build | CMAKE_BUILD_TYPE=" << CAMPROJ_BUILD_TYPE << " |\n"
      << "| scenes | " << run.scenes << " per band (indices " << options.first_scene << "-"
      << options.first_scene + run.scenes - 1
      << (options.first_scene >= 100 ? ", held out: the rules were chosen on 0-99"
                                     : options.first_scene + run.scenes <= 100
                                         ? ", the development set the rules were chosen on"
                                         : "")
      << "), " << bands.size() << " bands, " << run.scenes * static_cast<int>(bands.size())
      << " scenes; " << Format(run.seconds, "%.0f") << " s wall time, single-threaded |\n"
      << "| load average | " << run.load_before << " at the start (1, 5, 15 min) |\n"
      << "| silent failures of the default | " << run.silent << " |\n\n"
      << "## Results\n\n"
      << main_table << '\n'
      << context_table << '\n';
  out << MessagesSection(
      "### The default's refusals\n\nNumbers in the messages replaced by '#'; first 140 "
      "characters.\n\n| band | count | reason: message |\n|---|---:|---|\n",
      bands, stats, &BandStats::refusal_messages);
  out << MessagesSection(
      "### Errors (exceptions other than SceneError)\n\n| band | count | method: message "
      "|\n|---|---:|---|\n",
      bands, stats, &BandStats::error_messages);
  out << kLegend;
  return out.str();
}

void WriteTextFile(const std::filesystem::path& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
  if (!out) throw std::runtime_error("cannot write " + path.string());
}

int Main(const ClicksOptions& options) {
  cv::setNumThreads(1);
  std::filesystem::create_directories(options.out_dir);
#ifndef NDEBUG
  std::cerr << "bench --clicks: warning: assertions are on (not a Release build); times are not "
               "representative\n";
#endif
  const Clock::time_point begin = Clock::now();
  RunFacts run;
  run.load_before = LoadAverage();
  const std::vector<Band> bands = MakeBands();
  run.scenes = options.scenes > 0 ? options.scenes : options.quick ? 5 : 100;

  // Warm-up, untimed: page faults and lazy initialization off the first band's clock.
  {
    const Case c = MakeCase(bands, 0, 0);
    for (MethodId m : kMethodIds) Run(m, c, bands[0]);
  }

  std::ostringstream csv;
  csv << kCsvHeader;
  const std::vector<BandStats> stats = RunBands(options, bands, run.scenes, &csv);
  run.seconds = MillisecondsBetween(begin, Clock::now()) / 1000.0;

  const std::string main_table = MainTable(bands, stats);
  const std::string context_table = ContextTable(bands, stats);
  int errors = 0;
  for (const BandStats& s : stats) {
    run.silent += s.silent;
    errors += s.errors;
    for (const auto& [message, count] : s.error_messages) {
      if (message.rfind("oracle: ", 0) == 0) errors += count;
    }
  }

  const std::filesystem::path dir(options.out_dir);
  WriteTextFile(dir / "clicks.csv", csv.str());
  WriteTextFile(dir / "clicks.md",
                ReportText(options, bands, stats, run, main_table, context_table));

  std::cout << main_table << '\n' << context_table;
  std::cerr << "bench --clicks: " << run.scenes * bands.size() << " scenes in "
            << Format(run.seconds, "%.1f") << " s, " << run.silent
            << " silent failure(s) of the default, " << errors << " error(s) -> "
            << options.out_dir << "/{clicks.md,clicks.csv}\n";
  if (options.quick && (run.silent > 0 || errors > 0)) {
    std::cerr << "bench --clicks: check failed: " << run.silent << " silent failure(s), " << errors
              << " exception(s) other than SceneError\n";
    return 1;
  }
  return 0;
}

}  // namespace

int ClicksMain(int argc, char** argv) {
  ClicksOptions options;
  options.command = "bench";
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    options.command += " " + arg;
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::cerr << "bench --clicks: " << arg << " needs a value\n" << kClicksUsage;
        std::exit(1);
      }
      options.command += std::string(" ") + argv[i + 1];
      return argv[++i];
    };
    if (arg == "--clicks") {
      continue;
    } else if (arg == "-h" || arg == "--help") {
      std::cout << kClicksUsage;
      return 0;
    } else if (arg == "--quick") {
      options.quick = true;
    } else if (arg == "--out") {
      options.out_dir = value();
    } else if (arg == "--dump") {
      options.dump_dir = value();
    } else if (arg == "--scenes" || arg == "--first-scene") {
      const std::string text = value();
      char* end = nullptr;
      const long number = std::strtol(text.c_str(), &end, 10);
      const long least = arg == "--scenes" ? 1 : 0;
      if (end == text.c_str() || *end != '\0' || number < least || number > 1000000) {
        std::cerr << "bench --clicks: " << arg << " must be an integer in [" << least
                  << ", 1000000], got \"" << text << "\"\n";
        return 1;
      }
      (arg == "--scenes" ? options.scenes : options.first_scene) = static_cast<int>(number);
    } else {
      std::cerr << "bench --clicks: unknown argument \"" << arg << "\"\n" << kClicksUsage;
      return 1;
    }
  }
  try {
    return Main(options);
  } catch (const std::exception& e) {
    std::cerr << "bench --clicks: error: " << e.what() << '\n';
    return 2;
  }
}

}  // namespace bench
}  // namespace camproj

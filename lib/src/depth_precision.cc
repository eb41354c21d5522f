#include "camproj/depth_precision.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>

#include "check.h"

namespace camproj {

using internal::Concat;
using internal::Require;

namespace {

constexpr double kFixed24Max = 16777215.0;  // 2^24 - 1

void CheckRange(double z_near, double z_far) {
  Require(std::isfinite(z_near) && z_near > 0.0, "near must be finite and > 0, got ", z_near);
  Require(z_far > z_near && (std::isfinite(z_far) || z_far == kInfinity),
          "far must be greater than near (", z_near, ") and finite or infinite, got ", z_far);
}

// Window depth d = alpha + beta / z (docs/conventions.md, section 6), so z = beta / (d - alpha).
struct DepthMap {
  double z_near;
  double z_far;
  bool reversed;
  double alpha;
  double beta;

  DepthMap(double n, double f, bool reversed_z) : z_near(n), z_far(f), reversed(reversed_z) {
    const bool infinite = std::isinf(f);
    if (!reversed) {
      alpha = infinite ? 1.0 : f / (f - n);
      beta = infinite ? -n : -f * n / (f - n);
    } else {
      alpha = infinite ? 0.0 : -n / (f - n);
      beta = infinite ? n : f * n / (f - n);
    }
  }

  // The table's factored forms, which are exact at the planes (0 at near, 1 at far, ...).
  double DepthAt(double z) const {
    const double n = z_near;
    const double f = z_far;
    double d;
    if (std::isinf(f)) {
      d = reversed ? n / z : (z - n) / z;
    } else {
      d = reversed ? n * (f - z) / ((f - n) * z) : f * (z - n) / ((f - n) * z);
    }
    return std::clamp(d, 0.0, 1.0);
  }

  // |z(d1 + dd) - z(d1)|, from the difference dd of two representable values (exact) rather than
  // from two nearly equal distances.
  double DistanceBetween(double d1, double dd) const {
    const double e1 = d1 - alpha;
    const double e2 = d1 + dd - alpha;
    if (e1 == 0.0 || e2 == 0.0) return kInfinity;  // one of them is infinitely far
    return std::abs(beta * dd / (e1 * e2));
  }
};

// One quantization: the value representable at x and its neighbours below and above, NaN where
// a neighbour would leave the range [lo, hi].
struct Neighbours {
  double value;
  double below;
  double above;
};

float FlushDenormal(float x) { return std::abs(x) < FLT_MIN ? 0.0f : x; }

float NextFloat(float q, int direction) {
  if (q == 0.0f) return direction > 0 ? FLT_MIN : -FLT_MIN;
  return FlushDenormal(std::nextafter(q, direction > 0 ? HUGE_VALF : -HUGE_VALF));
}

double InRange(double x, double lo, double hi) { return x >= lo && x <= hi ? x : std::nan(""); }

Neighbours Float32Neighbours(double x, double lo, double hi) {
  const float q = FlushDenormal(static_cast<float>(x));
  return {q, InRange(NextFloat(q, -1), lo, hi), InRange(NextFloat(q, 1), lo, hi)};
}

Neighbours Fixed24Neighbours(double x) {
  const double k = std::round(x * kFixed24Max);
  return {k / kFixed24Max, InRange(k - 1.0, 0.0, kFixed24Max) / kFixed24Max,
          InRange(k + 1.0, 0.0, kFixed24Max) / kFixed24Max};
}

// The distances that round to `v` (a quantized z_ndc or depth, with depth = scale v + offset):
// those between the midpoints to its neighbours. At the end of the range, twice the half inside.
double BandWidth(const DepthMap& map, const Neighbours& v, double scale, double offset) {
  const double d = scale * v.value + offset;
  // Differences of neighbouring values: exact for floats, one rounding for 24-bit.
  const double half_below = 0.5 * scale * (v.value - v.below);
  const double half_above = 0.5 * scale * (v.above - v.value);
  if (std::isnan(half_below)) return 2.0 * map.DistanceBetween(d, half_above);
  if (std::isnan(half_above)) return 2.0 * map.DistanceBetween(d - half_below, half_below);
  return map.DistanceBetween(d - half_below, half_below + half_above);
}

}  // namespace

double DepthStepAt(double z, double z_near, double z_far, const GlDepth& depth,
                   DepthBuffer buffer) {
  CheckRange(z_near, z_far);
  Require(std::isfinite(z) && z >= z_near && z <= z_far, "distance z must be finite and within "
          "[near, far] = [", z_near, ", ", z_far, "], got ", z);
  const DepthMap map(z_near, z_far, depth.reversed_z);
  const double d = map.DepthAt(z);
  // z_ndc as a float32: d = (z_ndc + 1)/2 (NO) or z_ndc (ZO).
  const double ndc_step =
      depth.clip_depth == ClipDepth::kNegativeOneToOne
          ? BandWidth(map, Float32Neighbours(2.0 * d - 1.0, -1.0, 1.0), 0.5, 0.5)
          : BandWidth(map, Float32Neighbours(d, 0.0, 1.0), 1.0, 0.0);
  const double stored_step = BandWidth(map,
                                       buffer == DepthBuffer::kFloat32
                                           ? Float32Neighbours(d, 0.0, 1.0)
                                           : Fixed24Neighbours(d),
                                       1.0, 0.0);
  return std::max(ndc_step, stored_step);
}

namespace {

// Two significant digits: "0.15", "1.8e-05", "370" (not "3.7e+02"); "overflow" where the step
// is beyond a double (a far/near ratio near the doubles' range: the arithmetic gives inf or
// NaN, which read "resolves only nan world units" before session 37).
std::string TwoDigits(double value) {
  if (!std::isfinite(value)) return "overflow";
  char text[32];
  std::snprintf(text, sizeof(text), "%.2g", value);
  if (std::string(text).find("e+") != std::string::npos && value < 1e9) {
    std::snprintf(text, sizeof(text), "%.0f", std::strtod(text, nullptr));
  }
  return text;
}

// What a 24-bit buffer resolves at z: "resolves only X world units", or where the step
// overflows a double, "resolves no depth".
std::string ResolvesText(double z, double z_near, double z_far, const GlDepth& depth) {
  const double step = DepthStepAt(z, z_near, z_far, depth, DepthBuffer::kFixed24);
  if (!std::isfinite(step)) return "resolves no depth (its step there is beyond a double)";
  return "resolves only " + TwoDigits(step) + " world units";
}

std::string Ratio(double value) {
  if (!std::isfinite(value)) return "beyond a double";
  char text[32];
  std::snprintf(text, sizeof(text), "%.2g", value);
  return text;
}

std::string Distance(double value) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.4g", value);
  return text;
}

// The float32 spacing of z itself: the vertex pipeline cannot resolve less.
double Float32SpacingOf(double z) {
  const float f = static_cast<float>(z);
  return static_cast<double>(std::nextafter(f, HUGE_VALF)) - static_cast<double>(f);
}

std::string DepthName(const GlDepth& depth) {
  return Concat(depth.clip_depth == ClipDepth::kZeroToOne ? "ZO" : "NO",
                depth.reversed_z ? " reversed-Z" : "");
}

bool IsZoReversed(const GlDepth& depth) {
  return depth.clip_depth == ClipDepth::kZeroToOne && depth.reversed_z;
}

constexpr char kFloatZoReversedAdvice[] =
    "reversed-Z with a float depth buffer (GL_DEPTH_COMPONENT32F) and "
    "glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE)";

constexpr char kThreeReversedAdvice[] =
    "new THREE.WebGLRenderer({ reversedDepthBuffer: true }) (needs EXT_clip_control: check "
    "renderer.capabilities.reversedDepthBuffer) with an export made with --depth zo --reversed-z; "
    "it rebuilds projectionMatrix from fov, aspect and view on the first render";
constexpr char kThreeLogAdvice[] =
    "or new THREE.WebGLRenderer({ logarithmicDepthBuffer: true }) with the default --depth no "
    "(depth written per fragment, which costs early depth testing)";

// What to do about a large depth range, given the convention in use.
std::string Remedy(const GlDepth& depth, DepthAdviceTarget target) {
  if (target == DepthAdviceTarget::kThreeJs) {
    return IsZoReversed(depth)
               ? "create the renderer with reversedDepthBuffer: true (three r187: WebGLRenderer "
                 "with EXT_clip_control, or WebGPURenderer)"
               : Concat("use ", kThreeReversedAdvice, ", ", kThreeLogAdvice);
  }
  if (IsZoReversed(depth)) {
    return "keep your ZO reversed-Z projection and make sure the depth buffer is float32 "
           "(GL_DEPTH_COMPONENT32F)";
  }
  if (depth.reversed_z) {
    return Concat("NO reversed-Z does not help (z_ndc near -1 is as coarse as 24-bit): use ",
                  kFloatZoReversedAdvice);
  }
  return Concat("use ", kFloatZoReversedAdvice);
}

constexpr GlDepth kStandardNo{ClipDepth::kNegativeOneToOne, false};
constexpr GlDepth kReversedZo{ClipDepth::kZeroToOne, true};

// DepthAdvice::warnings (depth_precision.h).
std::vector<std::string> DepthRangeWarnings(double z_near, double z_far, const GlDepth& depth,
                                            DepthAdviceTarget target) {
  std::vector<std::string> warnings;
  const bool infinite = std::isinf(z_far);
  if (!infinite && z_far / z_near > kDepthRatioWarning) {
    warnings.push_back(Concat(
        "far/near = ", Ratio(z_far / z_near), " (near ", Distance(z_near), ", far ",
        Distance(z_far), ") is above ", Ratio(kDepthRatioWarning),
        ": a 24-bit depth buffer ", ResolvesText(z_far, z_near, z_far, kStandardNo),
        " at the far plane; ", Remedy(depth, target), ", or raise near"));
  }
  if (infinite && !IsZoReversed(depth)) {
    const double z = 1000.0 * z_near;
    warnings.push_back(Concat(
        "infinite far plane without ZO reversed-Z: the depth step grows as z^2/near (",
        TwoDigits(DepthStepAt(z, z_near, z_far, depth, DepthBuffer::kFloat32)),
        " world units at 1000 near = ", Distance(z), " even with a float32 buffer); ", Remedy(depth, target)));
  }
  return warnings;
}

// The table's rows: near, their geometric mean, half far and far (distinct, in order); for an
// infinite far, near times 1, 10, 100 and 1000.
std::vector<double> TableDistances(double z_near, double z_far) {
  if (std::isinf(z_far)) return {z_near, 10.0 * z_near, 100.0 * z_near, 1000.0 * z_near};
  std::vector<double> distances;
  for (double z : {z_near, std::sqrt(z_near * z_far), 0.5 * z_far, z_far}) {
    if (z >= z_near && z <= z_far &&
        std::find(distances.begin(), distances.end(), z) == distances.end()) {
      distances.push_back(z);
    }
  }
  std::sort(distances.begin(), distances.end());
  return distances;
}

// DepthAdvice::table: the depth step at TableDistances for the standard conventions and
// `depth`'s, in aligned columns.
std::string DepthStepTable(double z_near, double z_far, const GlDepth& depth) {
  struct Column {
    std::string name;
    GlDepth depth;
    DepthBuffer buffer;
  };
  std::vector<Column> columns = {{"24-bit NO", kStandardNo, DepthBuffer::kFixed24},
                                 {"float32 NO", kStandardNo, DepthBuffer::kFloat32},
                                 {"float32 ZO reversed-Z", kReversedZo, DepthBuffer::kFloat32}};
  const bool yours_shown = (depth.clip_depth == kStandardNo.clip_depth &&
                            depth.reversed_z == kStandardNo.reversed_z) ||
                           IsZoReversed(depth);
  if (!yours_shown) {
    columns.push_back({"float32 " + DepthName(depth) + " (yours)", depth, DepthBuffer::kFloat32});
  }

  std::vector<std::vector<std::string>> cells;
  cells.push_back({"distance"});
  for (const Column& column : columns) cells[0].push_back(column.name);
  bool any_marked = false;
  for (double z : TableDistances(z_near, z_far)) {
    std::string label = Distance(z);
    if (z == z_near) label += " (near)";
    if (z == z_far) label += " (far)";
    std::vector<std::string> row = {label};
    for (const Column& column : columns) {
      const double step = DepthStepAt(z, z_near, z_far, column.depth, column.buffer);
      const double z_spacing = Float32SpacingOf(z);
      const bool marked = step < z_spacing;
      any_marked = any_marked || marked;
      // Far below z's own spacing only where the float depth is 0 (reversed-Z at far): "~0".
      row.push_back((step < 1e-6 * z_spacing ? std::string("~0") : TwoDigits(step)) +
                    (marked ? "*" : ""));
    }
    cells.push_back(row);
  }
  std::vector<size_t> widths(cells[0].size(), 0);
  for (const auto& row : cells) {
    for (size_t i = 0; i < row.size(); ++i) widths[i] = std::max(widths[i], row[i].size());
  }
  std::ostringstream table;
  table << "depth step in world units (how far a point must move along the view axis to change "
           "the stored depth; near "
        << Distance(z_near) << ", far " << (std::isinf(z_far) ? "inf" : Distance(z_far))
        << "):\n";
  for (const auto& row : cells) {
    std::string line;
    for (size_t i = 0; i < row.size(); ++i) {
      line += row[i];
      if (i + 1 < row.size()) line += std::string(widths[i] - row[i].size() + 3, ' ');
    }
    table << "  " << line << "\n";
  }
  if (any_marked) {
    table << "* finer than float32 spacing of the distance itself: there the vertex arithmetic, "
             "not the depth buffer, limits precision\n";
  }
  return table.str();
}

// DepthAdvice::advice.
std::string AdviceLine(const GlDepth& depth, DepthAdviceTarget target) {
  if (target == DepthAdviceTarget::kThreeJs) {
    return IsZoReversed(depth)
               ? Concat("ZO reversed-Z in three.js: ", Remedy(depth, target),
                        "; it rebuilds projectionMatrix from fov, aspect and view on the first "
                        "render")
               : Concat("where depth precision matters in three.js: ",
                        Remedy(depth, target).substr(4));
  }
  return IsZoReversed(depth)
             ? "ZO reversed-Z: use it with a float depth buffer (GL_DEPTH_COMPONENT32F), "
               "glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE), glDepthFunc(GL_GREATER) "
               "and glClearDepth(0)"
             : "where depth precision matters, use reversed-Z with ZO and a float depth "
               "buffer: glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE), "
               "glDepthFunc(GL_GREATER), glClearDepth(0), GL_DEPTH_COMPONENT32F";
}

}  // namespace

DepthAdvice AdviseDepth(double z_near, double z_far, const GlDepth& depth,
                        DepthAdviceTarget target) {
  CheckRange(z_near, z_far);
  DepthAdvice advice;
  advice.warnings = DepthRangeWarnings(z_near, z_far, depth, target);
  advice.table = DepthStepTable(z_near, z_far, depth);
  advice.advice = AdviceLine(depth, target);
  return advice;
}

}  // namespace camproj

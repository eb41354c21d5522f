#include "camproj/depth_precision.h"

#include <cfloat>
#include <cmath>
#include <cstdint>
#include <functional>
#include <random>
#include <stdexcept>
#include <string>
#include <utility>

#include <gtest/gtest.h>

#include "camproj/gl.h"
#include "seeds.h"
#include "test_scenes.h"

namespace camproj {
namespace {

const GlDepth kStandardNo{ClipDepth::kNegativeOneToOne, false};
const GlDepth kStandardZo{ClipDepth::kZeroToOne, false};
const GlDepth kReversedNo{ClipDepth::kNegativeOneToOne, true};
const GlDepth kReversedZo{ClipDepth::kZeroToOne, true};

// The issue's figures are "~" values (0.15 world units, 18 micrometres), stated to two digits.
constexpr double kIssueFigureRelative = 0.1;
// The hand formulas below use the derivative d(depth)/dz; the library inverts the mapping at two
// representable depths. They differ by the change of the derivative over one step, Δd / (d - α):
// 6e-8 / 1e-4 = 6e-4 for the 24-bit case, ~1e-7 for the float one.
constexpr double kDerivativeRelative = 1e-3;
// Library and simulation both measure the band between the midpoints around the stored value.
// Bisection finds each end to one double of z (1.1e-16 z); the narrowest bands below are ~3e-9 z
// (near the near plane), so the two agree to ~1e-7 (observed 1.1e-7); 1e-5 leaves a margin.
constexpr double kBinWidthRelative = 1e-5;

// ---- An independent simulation of GL's depth pipeline: the projection matrix's depth row in long
// double, then the float32 z_ndc and the buffer's rounding.

struct Pipeline {
  double z_near;
  double z_far;
  GlDepth depth;
  DepthBuffer buffer;

  long double Ndc(double z) const {
    const Eigen::Matrix4d m = ClipFromGlEye(Frustum{-1.0, 1.0, -1.0, 1.0, z_near, z_far}, depth);
    const long double z_eye = -static_cast<long double>(z);
    return (static_cast<long double>(m(2, 2)) * z_eye + m(2, 3)) / -z_eye;
  }
  static double Float32(long double x) {
    const float f = static_cast<float>(x);
    return std::abs(f) < FLT_MIN ? 0.0 : f;  // denormals flushed, as the library's contract says
  }
  // The two quantizations DepthStepAt names: z_ndc as a float32, and the stored window depth.
  double NdcStage(double z) const { return Float32(Ndc(z)); }
  double StoredStage(double z) const {
    const long double ndc = Ndc(z);
    long double window = depth.clip_depth == ClipDepth::kNegativeOneToOne ? (ndc + 1) / 2 : ndc;
    window = std::min<long double>(std::max<long double>(window, 0), 1);
    if (buffer == DepthBuffer::kFloat32) return Float32(window);
    return static_cast<double>(std::llroundl(window * 16777215.0L));
  }
};

using Quantizer = std::function<double(double)>;

// The interval of distances around z that `q` maps to the value of z, found by doubling a step
// until the value changes and bisecting to adjacent doubles.
std::pair<double, double> BinAround(const Quantizer& q, double z) {
  const double value = q(z);
  double bounds[2];
  for (int side = 0; side < 2; ++side) {
    const double sign = side == 0 ? -1.0 : 1.0;
    double inside = z;
    double outside = z;
    for (double delta = 1e-15 * z;; delta *= 2.0) {
      outside = z + sign * delta;
      if (q(outside) != value) break;
      inside = outside;
    }
    for (;;) {
      const double mid = 0.5 * (inside + outside);
      if (mid == inside || mid == outside) break;
      (q(mid) == value ? inside : outside) = mid;
    }
    bounds[side] = 0.5 * (inside + outside);
  }
  return {bounds[0], bounds[1]};
}

// ---- The issue's measured numbers.

TEST(DepthPrecisionTest, IssueFiguresAtNear01Far1000Z500) {
  const double n = 0.1, f = 1000.0, z = 500.0;
  const double fixed_standard = DepthStepAt(z, n, f, kStandardNo, DepthBuffer::kFixed24);
  const double float_reversed = DepthStepAt(z, n, f, kReversedZo, DepthBuffer::kFloat32);
  EXPECT_NEAR(fixed_standard, 0.15, kIssueFigureRelative * 0.15);     // ~15 cm
  EXPECT_NEAR(float_reversed, 1.8e-5, kIssueFigureRelative * 1.8e-5);  // ~18 micrometres

  // By hand: dz = Δd / |d(depth)/dz|, |d(depth)/dz| = f n / ((f - n) z^2) for both mappings.
  const double slope = f * n / ((f - n) * z * z);
  // 24-bit: Δd = 1 / (2^24 - 1). The float32 z_ndc (NO: 2d - 1 near 1, spacing 2^-24, i.e.
  // 2^-25 in depth) is finer, so the buffer sets the step.
  EXPECT_NEAR(fixed_standard, (1.0 / 16777215.0) / slope, kDerivativeRelative * fixed_standard);
  // Reversed-Z ZO: depth = n (f - z) / ((f - n) z) = 1.0001e-4 lies in [2^-14, 2^-13): the float
  // spacing there is 2^-14 * 2^-23 = 2^-37.
  EXPECT_NEAR(float_reversed, std::ldexp(1.0, -37) / slope, kDerivativeRelative * float_reversed);
}

// ---- The definition: at the step the stored value changes, at half of it it does not.

TEST(DepthPrecisionTest, StepIsTheWidthOfTheSimulatedQuantizationBin) {
  std::mt19937_64 rng(testing::Seed(7));
  const std::pair<double, double> ranges[] = {{0.1, 1000.0}, {1.0, 20.0}, {1e-3, 1e3}};
  const std::pair<GlDepth, DepthBuffer> configs[] = {
      {kStandardNo, DepthBuffer::kFixed24}, {kStandardNo, DepthBuffer::kFloat32},
      {kReversedZo, DepthBuffer::kFloat32}, {kStandardZo, DepthBuffer::kFloat32},
      {kReversedNo, DepthBuffer::kFloat32}, {kReversedZo, DepthBuffer::kFixed24}};
  for (const auto& [n, f] : ranges) {
    for (const auto& [depth, buffer] : configs) {
      const Pipeline pipeline{n, f, depth, buffer};
      const Quantizer ndc_stage = [&](double z) { return pipeline.NdcStage(z); };
      const Quantizer stored_stage = [&](double z) { return pipeline.StoredStage(z); };
      for (int i = 0; i < 20; ++i) {
        // Away from the planes, where the bins are clipped and (reversed-Z at far) the float
        // depth approaches 0 and bins shrink below what bisection in double resolves.
        const double z0 = testing::LogUniform(rng, n * 1.001, f * 0.9);
        SCOPED_TRACE(::testing::Message() << "near " << n << " far " << f << " z " << z0 << " "
                                        << ToString(depth.clip_depth)
                                        << (depth.reversed_z ? " reversed" : "") << " "
                                        << (buffer == DepthBuffer::kFixed24 ? "24" : "f32"));
        const auto ndc_bin = BinAround(ndc_stage, z0);
        const auto stored_bin = BinAround(stored_stage, z0);
        const double ndc_width = ndc_bin.second - ndc_bin.first;
        const double stored_width = stored_bin.second - stored_bin.first;
        const double step = DepthStepAt(z0, n, f, depth, buffer);
        const double expected = std::max(ndc_width, stored_width);
        EXPECT_NEAR(step, expected, kBinWidthRelative * expected);

        // At the centre of the coarser bin: +-0.45 step keeps its value, +-0.55 and +-1 step
        // change it.
        const Quantizer& coarser = ndc_width > stored_width ? ndc_stage : stored_stage;
        const auto bin = ndc_width > stored_width ? ndc_bin : stored_bin;
        const double zc = 0.5 * (bin.first + bin.second);
        const double value = coarser(zc);
        for (double sign : {-1.0, 1.0}) {
          EXPECT_EQ(coarser(zc + sign * 0.45 * step), value);
          EXPECT_NE(coarser(zc + sign * 0.55 * step), value);
          EXPECT_NE(coarser(zc + sign * step), value);
        }
        // From anywhere in a bin, one step reaches the next value.
        EXPECT_NE(coarser(z0 + step), coarser(z0));
      }
    }
  }
}

// ---- Comparisons the advice rests on.

TEST(DepthPrecisionTest, ReversedZFloatZoIsFarFinerThanStandardAwayFromTheCamera) {
  const double n = 0.1, f = 1000.0;
  for (double z : {0.25 * f, 0.5 * f, 0.9 * f, 0.99 * f}) {
    SCOPED_TRACE(z);
    const double reversed = DepthStepAt(z, n, f, kReversedZo, DepthBuffer::kFloat32);
    EXPECT_LT(1000.0 * reversed, DepthStepAt(z, n, f, kStandardNo, DepthBuffer::kFixed24));
    EXPECT_LT(1000.0 * reversed, DepthStepAt(z, n, f, kStandardNo, DepthBuffer::kFloat32));
    // NO reversed-Z loses the gain: z_ndc near -1 is a float with spacing 6e-8, so it stays
    // within a factor 2 of 24-bit (docs/conventions.md, section 6).
    EXPECT_GT(DepthStepAt(z, n, f, kReversedNo, DepthBuffer::kFloat32),
              0.4 * DepthStepAt(z, n, f, kStandardNo, DepthBuffer::kFixed24));
  }
}

TEST(DepthPrecisionTest, InfiniteFarGivesFiniteStepsThatFollowTheMapping) {
  const double n = 0.1;
  for (double z : {n, 10.0 * n, 100.0 * n, 1000.0 * n, 1e6 * n}) {
    SCOPED_TRACE(z);
    // The hand formulas' derivative error Δd / (d - α) reaches 0.06 at 1e6 near for 24-bit.
    const bool hand_checked = z <= 1000.0 * n;
    for (const GlDepth& depth : {kStandardNo, kStandardZo, kReversedNo, kReversedZo}) {
      for (DepthBuffer buffer : {DepthBuffer::kFixed24, DepthBuffer::kFloat32}) {
        const double step = DepthStepAt(z, n, kInfinity, depth, buffer);
        EXPECT_TRUE(std::isfinite(step));
        EXPECT_GT(step, 0.0);
      }
    }
    if (!hand_checked) continue;
    // Standard 24-bit: depth = 1 - n/z, so dz = Δd z^2 / n with Δd = 1/(2^24 - 1).
    EXPECT_NEAR(DepthStepAt(z, n, kInfinity, kStandardNo, DepthBuffer::kFixed24),
                z * z / (n * 16777215.0), kDerivativeRelative * z * z / (n * 16777215.0));
    // Reversed-Z ZO float: depth = n/z, the float spacing is 2^-24..2^-23 of it, so dz is
    // 2^-24..2^-23 of z, at every distance.
    const double reversed = DepthStepAt(z, n, kInfinity, kReversedZo, DepthBuffer::kFloat32);
    EXPECT_GE(reversed, std::ldexp(z, -24) * (1.0 - kDerivativeRelative));
    EXPECT_LE(reversed, std::ldexp(z, -23) * (1.0 + kDerivativeRelative));
  }
  // So far out that 1 - n/z rounds to 1 (z >= 2^25 n): nothing farther stores another value.
  EXPECT_EQ(DepthStepAt(1e9 * n, n, kInfinity, kStandardNo, DepthBuffer::kFloat32), kInfinity);
}

// ---- Input checks.

TEST(DepthPrecisionTest, BadInputThrows) {
  const double nan = std::nan("");
  for (double n : {0.0, -1.0, nan, kInfinity}) {
    EXPECT_THROW(DepthStepAt(1.0, n, 10.0, {}, DepthBuffer::kFloat32), std::invalid_argument) << n;
    EXPECT_THROW(AdviseDepth(n, 10.0), std::invalid_argument) << n;
  }
  for (double f : {1.0, 0.5, nan, -kInfinity}) {
    EXPECT_THROW(DepthStepAt(1.0, 1.0, f, {}, DepthBuffer::kFixed24), std::invalid_argument) << f;
    EXPECT_THROW(AdviseDepth(1.0, f), std::invalid_argument) << f;
  }
  for (double z : {0.5, 11.0, nan, kInfinity}) {
    EXPECT_THROW(DepthStepAt(z, 1.0, 10.0, {}, DepthBuffer::kFloat32), std::invalid_argument) << z;
  }
  try {
    DepthStepAt(1.0, -2.5, 10.0, {}, DepthBuffer::kFloat32);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("-2.5"), std::string::npos) << e.what();
  }
}

// ---- The advice.

bool AnyContains(const std::vector<std::string>& lines, const std::string& text) {
  for (const std::string& line : lines) {
    if (line.find(text) != std::string::npos) return true;
  }
  return false;
}

TEST(DepthPrecisionTest, WarnsAboveFarOverNear1e5Only) {
  EXPECT_TRUE(AdviseDepth(0.1, 1000.0).warnings.empty());
  EXPECT_TRUE(AdviseDepth(1.0, 1e5).warnings.empty());  // exactly 1e5: not above
  EXPECT_TRUE(AdviseDepth(1.19, 1.96).warnings.empty());

  const DepthAdvice wide = AdviseDepth(1e-4, 1000.0);
  ASSERT_EQ(wide.warnings.size(), 1u);
  EXPECT_TRUE(AnyContains(wide.warnings, "far/near = 1e+07"));
  EXPECT_TRUE(AnyContains(wide.warnings, "glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE)"));
  EXPECT_TRUE(AnyContains(wide.warnings, "reversed-Z"));
  // Already ZO reversed-Z: still warned (a 24-bit buffer would not do), and told to use float.
  EXPECT_TRUE(AnyContains(AdviseDepth(1e-4, 1000.0, kReversedZo).warnings, "float32"));
  // NO reversed-Z is told that it does not help.
  EXPECT_TRUE(AnyContains(AdviseDepth(1e-4, 1000.0, kReversedNo).warnings, "does not help"));
}

TEST(DepthPrecisionTest, WarnsAboutInfiniteFarWithoutZoReversedZ) {
  EXPECT_TRUE(AnyContains(AdviseDepth(0.1, kInfinity).warnings, "infinite far"));
  EXPECT_TRUE(AnyContains(AdviseDepth(0.1, kInfinity, kReversedNo).warnings, "infinite far"));
  EXPECT_TRUE(AdviseDepth(0.1, kInfinity, kReversedZo).warnings.empty());
}

// For three.js the remedies are the renderer's options, not GL calls three users cannot make; the
// table is the same.
TEST(DepthPrecisionTest, ThreeJsAdviceNamesTheRendererOptions) {
  for (const GlDepth& depth : {GlDepth{}, kReversedNo, kReversedZo}) {
    const DepthAdvice gl = AdviseDepth(1e-4, 1000.0, depth);
    const DepthAdvice three = AdviseDepth(1e-4, 1000.0, depth, DepthAdviceTarget::kThreeJs);
    EXPECT_EQ(three.table, gl.table);
    ASSERT_EQ(three.warnings.size(), 1u);
    for (const std::string& text : {three.advice, three.warnings[0]}) {
      EXPECT_EQ(text.find("glClipControl"), std::string::npos) << text;
      EXPECT_NE(text.find("reversedDepthBuffer: true"), std::string::npos) << text;
    }
    if (!(depth.clip_depth == ClipDepth::kZeroToOne && depth.reversed_z)) {
      EXPECT_NE(three.advice.find("logarithmicDepthBuffer: true"), std::string::npos) << three.advice;
      EXPECT_NE(three.advice.find("--depth zo --reversed-z"), std::string::npos) << three.advice;
    }
  }
}

TEST(DepthPrecisionTest, TableShowsTheIssueFiguresAndTheAdvice) {
  const DepthAdvice advice = AdviseDepth(0.1, 1000.0);
  EXPECT_NE(advice.table.find("24-bit NO"), std::string::npos) << advice.table;
  EXPECT_NE(advice.table.find("float32 ZO reversed-Z"), std::string::npos) << advice.table;
  // The z = 500 row (far/2): 0.15 standard 24-bit, 1.8e-05 reversed-Z float ZO.
  const size_t row = advice.table.find("\n  500 ");
  ASSERT_NE(row, std::string::npos) << advice.table;
  const std::string line = advice.table.substr(row + 1, advice.table.find('\n', row + 1) - row);
  EXPECT_NE(line.find("0.15"), std::string::npos) << line;
  EXPECT_NE(line.find("1.8e-05"), std::string::npos) << line;
  for (const char* distance : {"0.1 (near)", "\n  10 ", "1000 (far)"}) {
    EXPECT_NE(advice.table.find(distance), std::string::npos) << distance << "\n" << advice.table;
  }
  EXPECT_NE(advice.advice.find("glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE)"), std::string::npos);
  // A column for the convention in use when it is none of the three compared.
  EXPECT_NE(AdviseDepth(0.1, 1000.0, kReversedNo).table.find("(yours)"), std::string::npos);
  EXPECT_EQ(AdviseDepth(0.1, 1000.0, kReversedZo).table.find("(yours)"), std::string::npos);
  // Infinite far: rows at near, 10, 100 and 1000 near, all finite numbers.
  const std::string infinite = AdviseDepth(0.1, kInfinity).table;
  EXPECT_NE(infinite.find("\n  100 "), std::string::npos) << infinite;
  EXPECT_EQ(infinite.find("inf "), std::string::npos) << infinite;
  EXPECT_EQ(infinite.find("nan"), std::string::npos) << infinite;
}

// Ranges near the doubles' limits: the advice says "overflow" / "resolves no depth" and never
// prints nan or inf (it read "resolves only nan world units" before session 37).
TEST(DepthPrecisionTest, ExtremeRangesPrintNoNonFiniteNumber) {
  for (const auto& [z_near, z_far] : {std::pair{1.198, 1e308}, std::pair{1e-300, 1.973},
                                      std::pair{1e-300, 1e300}}) {
    for (const GlDepth depth : {GlDepth{}, GlDepth{ClipDepth::kZeroToOne, true}}) {
      const DepthAdvice advice = AdviseDepth(z_near, z_far, depth);
      std::string text = advice.table + advice.advice;
      for (const std::string& w : advice.warnings) text += w;
      for (const char* bad : {"nan", "inf "}) {
        EXPECT_EQ(text.find(bad), std::string::npos) << z_near << " " << z_far << ":\n" << text;
      }
    }
  }
}

}  // namespace
}  // namespace camproj

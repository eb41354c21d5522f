#include "fit/model.h"

#include <array>
#include <cmath>
#include <string>

#include "camproj/number_text.h"
#include "check.h"

namespace camproj {
namespace internal {

namespace {

// Names of the fit-intrinsics slots, in reprojection_error.h's layout.
const std::array<const char*, kFitIntrinsicsSize> kSlotNames = {
    "focal", "aspect", "cx", "cy", "skew", "k1", "k2", "p1", "p2", "k3"};

// A value as internal::Concat writes it (printf's %.17g in the "C" locale), without a stream:
// DescribeFixed writes every fixed slot of a described fit, and a stream costs ~5000 instructions.
std::string ValueText(double value) { return GeneralDouble(value, 17); }

}  // namespace

Model MakeModel(const FitOptions& options, const ImageSize& size) {
  Model model;
  if (options.known_intrinsics) {
    const Intrinsics k = ConvertPixelOrigin(*options.known_intrinsics, options.pixel_origin,
                                            PixelOrigin::kCenter);
    model.value = {k.fx, k.fy / k.fx, k.cx, k.cy, k.skew, k.k1, k.k2, k.p1, k.p2, k.k3};
    return model;
  }
  const double shift = PixelOriginShift(options.pixel_origin, PixelOrigin::kCenter);
  auto set = [&](int slot, const ParameterMode& mode, double default_value, double fixed_value) {
    model.free[slot] = mode.IsFree();
    model.value[slot] = mode.kind == ParameterMode::Kind::kFixed ? fixed_value : default_value;
  };
  // A free focal length's start comes from the closed form; 1 is a placeholder.
  set(0, options.focal, 1.0, options.focal.value);
  set(1, options.aspect, 1.0, options.aspect.value);
  set(2, options.principal_point, 0.5 * (size.width - 1.0), options.principal_point.value + shift);
  set(3, options.principal_point, 0.5 * (size.height - 1.0),
      options.principal_point.value2 + shift);
  set(4, options.skew, 0.0, options.skew.value);
  set(5, options.k1, 0.0, options.k1.value);
  set(6, options.k2, 0.0, options.k2.value);
  return model;
}

std::vector<FixedParameter> DescribeFixed(const FitOptions& options, const ImageSize& size) {
  std::vector<FixedParameter> fixed;
  if (options.known_intrinsics) {
    const Intrinsics& k = *options.known_intrinsics;  // in options.pixel_origin, as given
    std::string text = Concat("fx ", k.fx, ", fy ", k.fy, ", cx ", k.cx, ", cy ", k.cy, ", skew ",
                              k.skew, ", k1 ", k.k1, ", k2 ", k.k2);
    if (k.HasBeyondTwoRadial()) text += Concat(", p1 ", k.p1, ", p2 ", k.p2, ", k3 ", k.k3);
    fixed.push_back({"intrinsics", text, "given: pose only"});
    return fixed;
  }
  const Model model = MakeModel(options, size);
  // The principal point in options.pixel_origin: a given one as given, the default shifted.
  const double shift = PixelOriginShift(PixelOrigin::kCenter, options.pixel_origin);
  auto describe = [&](int slot, const ParameterMode& mode, const char* default_why) {
    if (mode.IsFree()) return;
    std::string name = kSlotNames[slot];
    std::string value = ValueText(model.value[slot]);
    if (slot == 2) {  // cy is described with cx
      name = "principal point";
      value = mode.kind == ParameterMode::Kind::kFixed
                  ? ValueText(options.principal_point.value) + ", " +
                        ValueText(options.principal_point.value2)
                  : ValueText(0.5 * (size.width - 1.0) + shift) + ", " +
                        ValueText(0.5 * (size.height - 1.0) + shift);
    }
    fixed.push_back({name, value, mode.kind == ParameterMode::Kind::kFixed ? "given" : default_why});
  };
  describe(0, options.focal, "");
  describe(1, options.aspect, "default: square pixels");
  describe(2, options.principal_point, "default: image centre");
  describe(4, options.skew, "default: no skew");
  describe(5, options.k1, "default: no distortion");
  describe(6, options.k2, "default: no distortion");
  return fixed;
}

Model ProjectOntoModel(const Model& model, const Intrinsics& k0) {
  Model projected = model;
  if (projected.free[0]) {
    projected.value[0] = projected.free[1] ? k0.fx : std::sqrt(k0.fx * k0.fy / projected.value[1]);
  }
  if (projected.free[1]) projected.value[1] = k0.fy / projected.value[0];
  if (projected.free[2]) projected.value[2] = k0.cx;
  if (projected.free[3]) projected.value[3] = k0.cy;
  if (projected.free[4]) projected.value[4] = k0.skew;
  return projected;
}

std::string FreeLinearNames(const Model& model) {
  std::string names;
  const char* labels[] = {"focal", "aspect", "principal point", "", "skew"};
  for (int slot = 0; slot < 5; ++slot) {
    if (slot == 3 || !model.free[slot]) continue;
    if (!names.empty()) names += ", ";
    names += labels[slot];
  }
  return names;
}

}  // namespace internal
}  // namespace camproj

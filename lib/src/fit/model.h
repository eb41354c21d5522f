// The intrinsic model of the perspective fit (private): which slots of the fit-intrinsics block
// (reprojection_error.h's layout: focal, aspect, cx, cy, skew, k1, k2, p1, p2, k3; kCenter px;
// the last three are never free in a single-view fit, they hold given values or 0) are free, the
// value of every slot (the start of a free one, the given or default value of a fixed one).
// MakeModel builds it from FitOptions and ProjectOntoModel puts a closed-form K on it; every stage
// after the scene carries one: the start sets its free values, the refinement moves them and the
// assessment names them, with the fixed ones as DescribeFixed reports them.
#ifndef CAMPROJ_SRC_FIT_MODEL_H_
#define CAMPROJ_SRC_FIT_MODEL_H_

#include <algorithm>
#include <array>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "camproj/fit.h"
#include "camproj/intrinsics.h"
#include "fit/reprojection_error.h"

namespace camproj {
namespace internal {

// The intrinsic model: which slots are free and the value of every slot (the start for free
// ones).
struct Model {
  std::array<bool, kFitIntrinsicsSize> free{};
  std::array<double, kFitIntrinsicsSize> value{};

  int NumFree() const { return static_cast<int>(std::count(free.begin(), free.end(), true)); }
  // focal, aspect, principal point, skew: what a homography constrains (k1, k2 aside).
  int NumFreeLinear() const {
    return static_cast<int>(std::count(free.begin(), free.begin() + 5, true));
  }
  Intrinsics ToIntrinsics() const {
    Intrinsics k;
    k.fx = value[0];
    k.fy = value[1] * value[0];
    k.cx = value[2];
    k.cy = value[3];
    k.skew = value[4];
    k.k1 = value[5];
    k.k2 = value[6];
    k.p1 = value[7];
    k.p2 = value[8];
    k.k3 = value[9];
    return k;
  }
};

// The model `options` (checked) ask for, in kCenter px for an image of `size`. Known intrinsics
// fix every slot ("given: pose only"); otherwise each slot is free, fixed at its given value or
// at its default (square pixels, the image centre, no skew, no distortion). A free focal length
// holds 1, a placeholder for the closed-form start's value.
Model MakeModel(const FitOptions& options, const ImageSize& size);

// FitResult::fixed_parameters of MakeModel(options, size): every fixed slot with its value and
// why ("given", or the default's reason), cx and cy in options.pixel_origin; known intrinsics
// as one entry. Only a described fit
// reports them (assess.cc): a candidate of the model selection is scored without them, and at six
// points their text cost ~2 % of the default path when every fit made it.
std::vector<FixedParameter> DescribeFixed(const FitOptions& options, const ImageSize& size);

// The model with its free slots set from a closed-form K, the fixed ones kept: DLT's K projected
// onto the model (square pixels: the geometric mean of fx, fy).
Model ProjectOntoModel(const Model& model, const Intrinsics& k0);

// The pixel (kCenter) of a point in the cam frame under the model's intrinsics, or nothing if it
// is not in front of the camera.
inline std::optional<Eigen::Vector2d> PixelOfCamPoint(const Model& model,
                                                      const Eigen::Vector3d& p) {
  if (!(p.z() > 0.0)) return std::nullopt;
  double pixel[2];
  PixelFromFitIntrinsics(model.value.data(), p.x() / p.z(), p.y() / p.z(), pixel);
  return Eigen::Vector2d(pixel[0], pixel[1]);
}

// The free slots among focal, aspect, principal point and skew, for a refusal's message:
// "focal, aspect, principal point".
std::string FreeLinearNames(const Model& model);

}  // namespace internal
}  // namespace camproj

#endif  // CAMPROJ_SRC_FIT_MODEL_H_

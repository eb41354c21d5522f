#include "camproj/fit_request.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "camproj/errors.h"
#include "camproj/file_io.h"
#include "camproj/fit_report.h"
#include "camproj/number_text.h"
#include "camproj/world_origin.h"
#include "check.h"
#include "fit/scene.h"
#include "view/obj_mesh.h"
#include "view/ply_vertices.h"

namespace camproj {

namespace {

// Which of n points a fit left out (its `outliers`, indices below n).
std::vector<bool> LeftOutMask(size_t n, const std::vector<int>& outliers) {
  std::vector<bool> left_out(n, false);
  for (const int i : outliers) left_out.at(static_cast<size_t>(i)) = true;
  return left_out;
}

// The smallest box holding `points` (not empty).
BoxInWorld BoxOfPoints(const std::vector<Eigen::Vector3d>& points) {
  BoxInWorld box;
  box.min_in_world = box.max_in_world = points.front();
  for (const Eigen::Vector3d& p : points) {
    box.min_in_world = box.min_in_world.cwiseMin(p);
    box.max_in_world = box.max_in_world.cwiseMax(p);
  }
  return box;
}

const std::vector<std::string> kParameterNames = {"focal", "aspect", "principal-point",
                                                  "skew",  "k1",     "k2"};

ParameterMode* ModeOf(FitOptions& options, const std::string& name) {
  if (name == "focal") return &options.focal;
  if (name == "aspect") return &options.aspect;
  if (name == "principal-point") return &options.principal_point;
  if (name == "skew") return &options.skew;
  if (name == "k1") return &options.k1;
  if (name == "k2") return &options.k2;
  throw std::invalid_argument("unknown parameter \"" + name +
                              "\": expected focal, aspect, principal-point, skew, k1 or k2");
}

// Parses --model: "auto", or intrinsics joined by '+' ("focal+principal-point"; "pose": none),
// optionally after "pose+" as the summary prints models ("pose+focal+principal-point").
std::vector<std::string> ModelNames(const std::string& model) {
  std::vector<std::string> names;
  if (model == "pose") return names;
  size_t begin = model.rfind("pose+", 0) == 0 ? 5 : 0;
  for (;;) {
    const size_t end = model.find('+', begin);
    const std::string name = model.substr(begin, end == std::string::npos ? end : end - begin);
    if (std::find(kParameterNames.begin(), kParameterNames.end(), name) == kParameterNames.end()) {
      throw std::invalid_argument(
          "--model: unknown parameter \"" + name + "\" in \"" + model +
          "\": expected auto, pose, or parameters joined by '+' among focal, aspect, "
          "principal-point, skew, k1, k2 (e.g. focal+principal-point)");
    }
    if (std::find(names.begin(), names.end(), name) != names.end()) {
      throw std::invalid_argument("--model: \"" + name + "\" is named twice in \"" + model +
                                  "\"");
    }
    names.push_back(name);
    if (end == std::string::npos) return names;
    begin = end + 1;
  }
}

// The value "fixed at its default" means for an intrinsic of `options`' model: in the automatic
// path a default-mode intrinsic is a candidate, so a model or --fix given on the command line
// holds it at its default value (in the input's pixel origin).
ParameterMode DefaultValueOf(const std::string& name, const ImageSize& size, PixelOrigin origin) {
  const double shift = PixelOriginShift(PixelOrigin::kCenter, origin);
  if (name == "aspect") return ParameterMode::Fixed(1.0);
  if (name == "principal-point") {
    return ParameterMode::Fixed(0.5 * (size.width - 1) + shift, 0.5 * (size.height - 1) + shift);
  }
  return ParameterMode::Fixed(0.0);
}

// The SCALE of --loss KIND:SCALE: a finite number (as the command line's ParseNumbers reads it).
double LossScale(const std::string& text) {
  const char* begin = text.data();
  const char* end = text.data() + text.size();
  if (begin != end && *begin == '+') ++begin;
  double value = 0.0;
  const auto [ptr, error] = std::from_chars(begin, end, value);
  if (error != std::errc() || ptr != end || !std::isfinite(value)) {
    throw std::invalid_argument("--loss scale: \"" + text + "\" is not a finite number (in \"" +
                                text + "\")");
  }
  return value;
}

// --model: an orthographic camera, or the listed intrinsics free; "auto" leaves options as they
// are.
void SetModel(const FitArguments& args, const ImageSize& size, FitOptions* options_out) {
  FitOptions& options = *options_out;
  const std::string orthographic = "orthographic";
  if (args.model.rfind(orthographic, 0) == 0) {
    // "orthographic[+aspect][+skew]": the scale (focal) is always free.
    options.projection = Projection::kOrthographic;
    for (const std::string& name : kParameterNames) {
      *ModeOf(options, name) = name == "focal" || name == "principal-point"
                                   ? ParameterMode::Default()
                                   : DefaultValueOf(name, size, PixelOrigin::kCenter);
    }
    options.focal = ParameterMode::Free();
    if (args.model.size() > orthographic.size()) {
      if (args.model[orthographic.size()] != '+') {
        throw std::invalid_argument("--model: unknown model \"" + args.model + "\"");
      }
      for (const std::string& name : ModelNames(args.model.substr(orthographic.size() + 1))) {
        if (name != "aspect" && name != "skew") {
          throw std::invalid_argument("--model: an orthographic camera has aspect and skew, not " + name);
        }
        *ModeOf(options, name) = ParameterMode::Free();
      }
    }
  } else if (args.model != "auto") {
    // Exactly the listed intrinsics are free; the rest stay at their defaults (fixed there, so
    // that the automatic path does not free them).
    for (const std::string& name : kParameterNames) {
      *ModeOf(options, name) =
          name == "focal" ? ParameterMode::Default() : DefaultValueOf(name, size, options.pixel_origin);
    }
    for (const std::string& name : ModelNames(args.model)) *ModeOf(options, name) = ParameterMode::Free();
  }
}

// An intrinsic given a value by an option: --focal PX, --fovy DEG (which fixes the focal length
// and the aspect: fx = fy / aspect at aspect 1 or --aspect), --aspect, --principal-point,
// --skew, --k1, --k2.
struct GivenValue {
  std::string name;    // the intrinsic, as --free and --fix name it
  std::string option;  // "--focal"
  std::string value;   // "1500"; empty for --principal-point
};
std::vector<GivenValue> GivenValues(const FitArguments& args) {
  std::vector<GivenValue> given;
  if (args.focal > 0.0) given.push_back({"focal", "--focal", ShortestDouble(args.focal)});
  if (args.fovy_deg > 0.0) {
    given.push_back({"focal", "--fovy", ShortestDouble(args.fovy_deg)});
    given.push_back({"aspect", "--fovy", ShortestDouble(args.fovy_deg)});
  }
  if (args.aspect > 0.0) given.push_back({"aspect", "--aspect", ShortestDouble(args.aspect)});
  if (args.principal_point) given.push_back({"principal-point", "--principal-point", ""});
  if (!std::isnan(args.skew)) given.push_back({"skew", "--skew", ShortestDouble(args.skew)});
  if (!std::isnan(args.k1)) given.push_back({"k1", "--k1", ShortestDouble(args.k1)});
  if (!std::isnan(args.k2)) given.push_back({"k2", "--k2", ShortestDouble(args.k2)});
  return given;
}

// A name both freed (--free, or listed in --model) and fixed (--fix, or a value such as
// --aspect 1.01) would be fixed silently, the later option winning: refuse it instead.
void RefuseFreedAndFixed(const FitArguments& args) {
  std::vector<std::pair<std::string, std::string>> freed;  // (name, the option that frees it)
  for (const std::string& name : args.free) freed.emplace_back(name, "--free " + name);
  if (args.model != "auto" && args.model.rfind("orthographic", 0) != 0) {
    for (const std::string& name : ModelNames(args.model)) freed.emplace_back(name, "--model " + args.model);
  }
  std::vector<std::pair<std::string, std::string>> fixed;  // (name, the option that fixes it)
  for (const std::string& name : args.fix) fixed.emplace_back(name, "--fix " + name);
  for (const GivenValue& given : GivenValues(args)) {
    fixed.emplace_back(given.name, given.value.empty() ? given.option : given.option + " " + given.value);
  }
  for (const auto& [name, freed_by] : freed) {
    for (const auto& [fixed_name, fixed_by] : fixed) {
      if (name == fixed_name) {
        throw std::invalid_argument(name + " is both freed (" + freed_by + ") and fixed (" + fixed_by +
                                    "): give one");
      }
    }
  }
}

// --free, --fix and the intrinsics' values (--focal, --fovy, --aspect, --principal-point, --skew,
// --k1, --k2, --intrinsics) over the model's modes. `automatic`: the default path (a --fix then
// fixes at the default value, as the ladder would).
void SetIntrinsicValues(const FitArguments& args, const ImageSize& size, bool automatic,
                        FitOptions* options_out) {
  FitOptions& options = *options_out;
  if (args.known_intrinsics) {
    // --intrinsics gives every intrinsic: a value or mode beside it would be dropped.
    std::vector<std::string> given;
    if (args.model != "auto" && args.model != "pose") given.push_back("--model " + args.model);
    for (const GivenValue& value : GivenValues(args)) {
      if (given.empty() || given.back() != value.option) given.push_back(value.option);  // --fovy once
    }
    if (!args.free.empty()) given.push_back("--free");
    if (!args.fix.empty()) given.push_back("--fix");
    if (!given.empty()) {
      std::string list = given[0];
      for (size_t i = 1; i < given.size(); ++i) list += ", " + given[i];
      throw std::invalid_argument("--intrinsics gives every intrinsic (the pose alone is fitted): "
                                  "leave out " + list + ", or leave out --intrinsics");
    }
    // Intrinsics are in pixels of one image size: at another (a calibration at 1920x1080 used
    // on a 640x480 capture) every pixel would be misread.
    const std::optional<ImageSize>& calibrated = args.known_intrinsics_image_size;
    if (calibrated && (calibrated->width != size.width || calibrated->height != size.height)) {
      throw std::invalid_argument(
          "--intrinsics " + args.known_intrinsics_path + (args.known_intrinsics_path.empty() ? "" : " ") +
          "is for a " + std::to_string(calibrated->width) + "x" +
          std::to_string(calibrated->height) + " image, but --image-size is " +
          std::to_string(size.width) + "x" + std::to_string(size.height) +
          ": give the size the intrinsics were calibrated at (or scale fx, fy, cx, cy to this "
          "size in a file of its own)");
    }
  }
  RefuseFreedAndFixed(args);
  for (const std::string& name : args.free) *ModeOf(options, name) = ParameterMode::Free();
  for (const std::string& name : args.fix) {
    if (name == "focal") {
      throw std::invalid_argument("--fix focal needs a value: use --focal PX or --fovy DEG");
    }
    *ModeOf(options, name) = automatic ? DefaultValueOf(name, size, options.pixel_origin)
                                               : ParameterMode::Default();
  }
  if (args.aspect > 0.0) options.aspect = ParameterMode::Fixed(args.aspect);
  if (args.focal > 0.0 && args.fovy_deg > 0.0) throw std::invalid_argument("give --focal or --fovy, not both");
  if (args.focal > 0.0) options.focal = ParameterMode::Fixed(args.focal);
  if (args.fovy_deg > 0.0) {
    if (!(args.fovy_deg < 180.0)) throw std::invalid_argument("--fovy must be in (0, 180) degrees");
    // fovy fixes fy = H / (2 tan(fovy / 2)); fx = fy / aspect (1 unless --aspect).
    const double fy = 0.5 * size.height / std::tan(0.5 * args.fovy_deg * M_PI / 180.0);
    const double aspect = args.aspect > 0.0 ? args.aspect : 1.0;
    options.focal = ParameterMode::Fixed(fy / aspect);
    // Fixed, not the default: in --model auto the default lets the ladder free the aspect, and
    // fy, so the field of view (45.09 degrees written for --fovy 45.5).
    options.aspect = ParameterMode::Fixed(aspect);
  }
  if (args.principal_point) {
    options.principal_point = ParameterMode::Fixed(args.principal_point->x(), args.principal_point->y());
  }
  if (!std::isnan(args.skew)) options.skew = ParameterMode::Fixed(args.skew);
  if (!std::isnan(args.k1)) options.k1 = ParameterMode::Fixed(args.k1);
  if (!std::isnan(args.k2)) options.k2 = ParameterMode::Fixed(args.k2);
  if (args.known_intrinsics) {
    // The intrinsics come in kCenter; the fitter reads known_intrinsics in options.pixel_origin.
    options.known_intrinsics =
        ConvertPixelOrigin(*args.known_intrinsics, PixelOrigin::kCenter, options.pixel_origin);
  }
}

// FitRequest::held_by_model: the intrinsics the forced --model leaves out that no --free,
// --fix or value names.
void SetHeldByModel(const FitArguments& args, FitRequest* request) {
  const std::string orthographic_name = "orthographic";
  const bool orthographic = args.model.rfind(orthographic_name, 0) == 0;
  // "orthographic+aspect" lists aspect; "orthographic" alone nothing.
  const std::vector<std::string> listed =
      !orthographic ? ModelNames(args.model)
      : args.model.size() > orthographic_name.size()
          ? ModelNames(args.model.substr(orthographic_name.size() + 1))
          : std::vector<std::string>();
  std::vector<std::string> named = args.free;
  named.insert(named.end(), args.fix.begin(), args.fix.end());
  for (const GivenValue& value : GivenValues(args)) named.push_back(value.name);
  auto in = [](const std::vector<std::string>& names, const std::string& name) {
    return std::find(names.begin(), names.end(), name) != names.end();
  };
  for (const std::string& name : kParameterNames) {
    // An orthographic camera's scale is always free and its principal point never determined.
    if (name == "focal" || (orthographic && name == "principal-point")) continue;
    if (in(listed, name) || in(named, name)) continue;
    request->held_by_model.push_back(name == "principal-point" ? "principal point" : name);
  }
  request->held_why = "default: not in --model " + args.model;
}

// The refinement: --loss, --refiner, --ransac, --sigma, --near, --far.
void SetSolver(const FitArguments& args, FitOptions* options_out) {
  FitOptions& options = *options_out;
  if (args.loss != "none") {
    const size_t colon = args.loss.find(':');
    const std::string kind = args.loss.substr(0, colon);
    if (kind != "huber" && kind != "cauchy") {
      throw std::invalid_argument("--loss: expected none, huber:SCALE or cauchy:SCALE (px), got \"" +
                                  args.loss + "\"");
    }
    options.loss = kind == "huber" ? LossType::kHuber : LossType::kCauchy;
    options.loss_scale_px = colon == std::string::npos ? 1.0 : LossScale(args.loss.substr(colon + 1));
  }
  if (args.refiner != "lm" && args.refiner != "ceres") {
    throw std::invalid_argument("--refiner: expected lm or ceres, got \"" + args.refiner + "\"");
  }
  options.refiner = args.refiner == "ceres" ? Refiner::kCeres : Refiner::kLevenbergMarquardt;
  if (args.ransac_px > 0.0) {
    options.ransac = true;
    options.ransac_threshold_px = args.ransac_px;
  }
  if (args.sigma > 0.0) options.pixel_sigma = args.sigma;
  if (args.z_near > 0.0) options.z_near = args.z_near;
  if (args.z_far > 0.0) options.z_far = args.z_far;
}

// --bounds or --bounds-mesh (the box near and far cover) and --origin.
void SetRegionAndOrigin(const FitArguments& args, const FitOptions& options, FitRequest* request) {
  if (args.bounds_in_world && !args.mesh_vertices_in_world.empty()) {
    throw std::invalid_argument("give --bounds or --bounds-mesh, not both");
  }
  if (args.bounds_in_world || !args.mesh_vertices_in_world.empty()) {
    const char* option = args.bounds_in_world ? "--bounds" : "--bounds-mesh";
    const BoxInWorld box = args.bounds_in_world ? *args.bounds_in_world
                                                : BoxOfPoints(args.mesh_vertices_in_world);
    try {
      box.Check();
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(std::string(option) + ": " + e.what());
    }
    if (options.z_near && options.z_far) {
      throw std::invalid_argument(std::string(option) +
                                  " sets near and far: give it or both --near and --far, not all three");
    }
    request->bounds_in_world = box;
  }
  if (args.world_origin && args.auto_world_origin) {
    throw std::invalid_argument("--origin: give auto or X,Y,Z, not both");
  }
  if (args.world_origin) {
    for (int axis = 0; axis < 3; ++axis) {
      internal::Require(std::isfinite((*args.world_origin)[axis]),
                        "--origin: coordinates must be finite, got ", (*args.world_origin)[axis]);
    }
  }
  request->world_origin = args.world_origin;
  request->auto_world_origin = args.auto_world_origin;
}

}  // namespace

FitRequest FitRequestFrom(const FitArguments& args, const ImageSize& size) {
  size.Check();
  FitRequest request;
  // Every fit runs the default path (outlier stage, consistency gate), a forced model as a
  // ladder of one; only a robust loss, which the selection cannot compare, runs FitCamera alone.
  request.automatic = args.loss == "none";
  const bool forced = args.model != "auto";
  FitOptions& options = request.auto_options.fit;
  options.pixel_origin = PixelOriginFromString(args.pixel_origin);
  SetModel(args, size, &options);
  if (args.criterion != "aic" && args.criterion != "bic") {
    throw std::invalid_argument("--criterion: expected aic or bic, got \"" + args.criterion + "\"");
  }
  request.auto_options.criterion = args.criterion == "aic" ? ModelCriterion::kAic : ModelCriterion::kBic;
  SetIntrinsicValues(args, size, request.automatic, &options);
  if (forced) SetHeldByModel(args, &request);
  SetSolver(args, &options);
  SetRegionAndOrigin(args, options, &request);
  options.max_iterations = args.max_iterations;
  if (!forced && options.loss != LossType::kNone) {
    throw std::invalid_argument(
        "--loss needs an explicit --model (automatic selection compares "
        "least-squares fits): e.g. --model focal+aspect+principal-point; "
        "mis-clicked points are found and left out by default");
  }
  if (!request.automatic && options.focal.kind == ParameterMode::Kind::kDefault) {
    options.focal = ParameterMode::Free();
  }
  request.auto_options.find_outliers = !args.keep_all;
  if (args.max_uncertainty > 0.0) request.auto_options.max_uncertainty_px = args.max_uncertainty;
  if (!args.object_points_in_world.empty()) {
    if (!request.automatic) {
      throw std::invalid_argument(
          "--object-points is for the default path's determination check, which a "
          "robust --loss does not run");
    }
    request.auto_options.object_points_in_world = args.object_points_in_world;
  } else if (request.automatic) {
    // The mesh's vertices are where the camera must be right (FitArguments); a robust --loss
    // runs no determination check, and its mesh sets near and far only.
    request.auto_options.object_points_in_world = args.mesh_vertices_in_world;
  }
  if (request.automatic) {
    request.auto_options.Check();
  } else {
    options.Check();
  }
  return request;
}

FitResult RunFitRequest(const std::vector<Eigen::Vector3d>& points_in_world,
                        const std::vector<Eigen::Vector2d>& pixels,
                        const std::vector<std::string>& ids, const ImageSize& size,
                        const FitRequest& request) {
  FitResult result;
  if (!request.automatic) {
    result = FitCamera(points_in_world, pixels, size, request.options());
  } else {
    AutoFitOptions options = request.auto_options;
    if (ids.size() == pixels.size()) options.point_names = ids;
    result = FitCameraAuto(points_in_world, pixels, size, options);
  }
  for (FixedParameter& p : result.fixed_parameters) {
    if (p.why == "given" && std::find(request.held_by_model.begin(), request.held_by_model.end(),
                                      p.name) != request.held_by_model.end()) {
      p.why = request.held_why;
    }
  }
  if (request.auto_world_origin) {
    // A mask, not a search of the outliers per point: RANSAC at 1e6 points leaves out ~1e5.
    const std::vector<bool> left_out = LeftOutMask(points_in_world.size(), result.outliers);
    std::vector<Eigen::Vector3d> kept;
    for (size_t i = 0; i < points_in_world.size(); ++i) {
      if (!left_out[i]) kept.push_back(points_in_world[i]);
    }
    result.camera.world_origin = AutoOriginOfPoints(kept);
  } else if (request.world_origin) {
    result.camera.world_origin = request.world_origin;
  }
  if (result.camera.world_origin) {
    result.views.gl_eye_from_origin_world =
        GlEyeFromOriginWorld(result.camera.cam_from_world, *result.camera.world_origin);
  }
  if (!request.bounds_in_world) return result;
  const FitOptions& options = request.options();
  const BoxInWorld& box = *request.bounds_in_world;
  const DepthRangeOfBox range =
      DepthRangeCoveringBox(result.camera.cam_from_world, box, options.depth_margin);
  Camera& camera = result.camera;
  if (!options.z_near) {
    const Eigen::Vector3d corner = box.Corner(range.nearest_corner);
    internal::Require(range.z_near.has_value(), "--bounds: the box's corner (", corner.x(), ", ",
                      corner.y(), ", ", corner.z(), ") is at depth ", range.min_depth,
                      ", not in front of the fitted camera, so no near plane covers the box: give "
                      "--near (what is nearer is clipped)");
    camera.z_near = *range.z_near;
  }
  if (!options.z_far) camera.z_far = range.z_far;
  internal::Require(camera.z_far > camera.z_near, "--bounds: far ", camera.z_far,
                    " (the box's farthest corner) is not beyond --near ", camera.z_near);
  result.views =
      ViewsOfCamera(camera, (result.views.look_at.target - result.views.look_at.eye).stableNorm());
  return result;
}

std::string NearFarNote(const FitRequest& request, const FitResult& fit) {
  const FitOptions& options = request.options();
  char range[128];
  std::snprintf(range, sizeof range, "near %.6g, far %.6g: ", fit.camera.z_near, fit.camera.z_far);
  char margin[64];
  std::snprintf(margin, sizeof margin, ", widened by %.6g %%", 100.0 * options.depth_margin);
  if (options.z_near && options.z_far) return range + std::string("as given (--near, --far)\n");
  if (request.bounds_in_world) {
    return range + std::string("cover the --bounds box (its 8 corners' depths") + margin + ")" +
           (options.z_near ? "; near as given" : options.z_far ? "; far as given" : "") + "\n";
  }
  if (options.z_near || options.z_far) {
    const std::string given = options.z_near ? "near as given (--near); far covers"
                                             : "far as given (--far); near covers";
    return range + given + " the fitted points' depths only" + margin +
           ": the rest of the model may be clipped: give --bounds X0,Y0,Z0,X1,Y1,Z1 or "
           "--bounds-mesh model.obj (or .ply) to cover it, or " +
           (options.z_near ? "--far" : "--near") + " as well\n";
  }
  return range + std::string("cover the fitted points' depths only") + margin +
         "; the rest of the model may be clipped: give --bounds X0,Y0,Z0,X1,Y1,Z1 or "
         "--bounds-mesh model.obj (or .ply) to cover it, or --near/--far\n";
}

namespace {

// The note of one plane (ClippedPointsNote): `clipped` holds (depth, index) of each kept point
// beyond it, the farthest beyond first.
std::string ClippedByPlane(bool near, double plane, bool given,
                           const std::vector<std::pair<double, int>>& clipped, int kept,
                           const std::vector<std::string>& ids) {
  using internal::Concat;
  const char* option = near ? "--near" : "--far";
  const std::string which =
      given ? Concat(option, " ", ShortestDouble(plane))
            : Concat("the ", near ? "near" : "far", " plane ", GeneralDouble(plane, 6),
                     " (covering the --bounds box)");
  std::string names;
  constexpr size_t kNamed = 3;
  for (size_t i = 0; i < std::min(clipped.size(), kNamed); ++i) {
    const auto [depth, index] = clipped[i];
    const std::string id = index < static_cast<int>(ids.size()) ? ids[index]
                                                                : std::to_string(index + 1);
    names += Concat(i == 0 ? "" : ", ", internal::PointName(id), i == 0 ? " at depth " : " at ",
                    GeneralDouble(depth, 6));
  }
  if (clipped.size() > kNamed) names += Concat(" and ", clipped.size() - kNamed, " more");
  // The bound in six digits, rounded away from the points (to nearest, --near 1.323749 read
  // "give --near below 1.32375" for a point at 1.3237484).
  const double depth = clipped.front().first;
  double bound = std::stod(GeneralDouble(depth, 6));
  if (near ? bound > depth : bound < depth) {
    const double step = std::pow(10.0, std::floor(std::log10(std::abs(depth))) - 5);
    bound = std::stod(GeneralDouble(near ? bound - step : bound + step, 6));
  }
  const std::string keep = Concat("give ", option, near ? " below " : " beyond ",
                                  GeneralDouble(bound, 6), " to draw them");
  return Concat(which, " clips ", clipped.size(), " of the ", kept, " fitted points, ",
                near ? "nearer" : "farther", " than it (", names,
                "): an OpenGL render of this camera draws them nowhere; ",
                given ? keep : Concat("widen --bounds to hold them, or ", keep), "\n");
}

}  // namespace

std::string ClippedPointsNote(const FitRequest& request, const FitResult& fit,
                              const std::vector<Eigen::Vector3d>& points_in_world,
                              const std::vector<std::string>& ids) {
  const FitOptions& options = request.options();
  // The planes a fit sets itself cover its points (DepthRangeOfPoints).
  if (!options.z_near && !options.z_far && !request.bounds_in_world) return "";
  const std::vector<bool> left_out = LeftOutMask(points_in_world.size(), fit.outliers);
  std::vector<std::pair<double, int>> nearer, farther;
  int kept = 0;
  for (size_t i = 0; i < points_in_world.size(); ++i) {
    if (left_out[i]) continue;
    ++kept;
    const double depth = (fit.camera.cam_from_world * points_in_world[i]).z();
    if (depth < fit.camera.z_near) nearer.emplace_back(depth, static_cast<int>(i));
    if (depth > fit.camera.z_far) farther.emplace_back(depth, static_cast<int>(i));
  }
  std::sort(nearer.begin(), nearer.end());
  std::sort(farther.begin(), farther.end(), std::greater<>());
  std::string note;
  if (!nearer.empty()) {
    note += ClippedByPlane(true, fit.camera.z_near, options.z_near.has_value(), nearer, kept, ids);
  }
  if (!farther.empty()) {
    note += ClippedByPlane(false, fit.camera.z_far, options.z_far.has_value(), farther, kept, ids);
  }
  return note;
}

std::string JudgedRegionNote(const FitRequest& request, const FitResult& fit) {
  // The clicks alone leave the rest of the object to extrapolation: on the click benchmark's
  // scenes 500-899 (docs/model-selection.md) 7 of 5771 answers were more than 10 px off beyond
  // the clicks, and none of 5618 with the model's vertices given.
  if (!fit.determination.checked || !request.auto_options.object_points_in_world.empty()) {
    return "";
  }
  return "the camera is judged (--max-uncertainty) over the box the points span only, and "
         "extrapolated beyond it: give --bounds-mesh model.obj (or .ply) or --object-points "
         "(the model's vertices) to have it judged there too\n";
}

std::vector<Eigen::Vector3d> ReadMeshVertices(const std::string& path) {
  std::string extension = std::filesystem::path(path).extension().string();
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  std::vector<Eigen::Vector3d> vertices;
  if (extension == ".ply") {
    vertices = internal::PlyVertexPositions(ReadWholeFile(path), path);
  } else {
    const internal::ObjMesh mesh = internal::ParseObjMesh(ReadWholeFile(path), path);
    vertices.reserve(mesh.positions.size() / 3);
    for (size_t i = 0; i + 2 < mesh.positions.size(); i += 3) {
      vertices.emplace_back(mesh.positions[i], mesh.positions[i + 1], mesh.positions[i + 2]);
    }
  }
  if (vertices.empty()) throw InputError(path + ": no vertices (a mesh's v lines or vertex element)");
  return vertices;
}

std::string FitCameraFileText(const FitResult& fit, PixelOrigin pixel_origin) {
  CameraFileOptions file_options;
  file_options.pixel_origin = pixel_origin;
  file_options.target_distance = (fit.views.look_at.target - fit.views.look_at.eye).stableNorm();
  const FitRecord record = FitRecordOf(fit);
  return CameraToJsonText(fit.camera, file_options, &record);
}

}  // namespace camproj

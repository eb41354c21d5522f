// camproj calibrate: one camera from many views (shared intrinsics, a pose per view).
#include <algorithm>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>

#include "camproj/calibrate.h"
#include "camproj/calibration_file.h"
#include "camproj/errors.h"
#include "camproj/file_io.h"
#include "camproj/points_file.h"
#include "camproj/terminal_text.h"
#include "cli.h"

namespace camproj::cli {

namespace {

struct CalibrateArgs {
  std::vector<std::string> view_paths;
  std::string image_size;
  std::string output_path;
  std::string poses_path;
  std::vector<std::string> fix;
  std::string model = "auto";
  double sigma = 0.0;
  bool keep_all_views = false;
  bool keep_all_points = false;
  std::string pixel_origin = "center";
};

// The model --model and --fix ask for (CalibrateOptionsForModel); a bad one is a usage error
// (exit 1, as for `fit --model`) naming both flags.
CalibrateOptions ModelOptions(const std::string& model, const std::vector<std::string>& fix) {
  try {
    return CalibrateOptionsForModel(model, fix);
  } catch (const std::invalid_argument& e) {
    std::string flags = "--model " + model;
    for (size_t i = 0; i < fix.size(); ++i) flags += (i == 0 ? " --fix " : ",") + fix[i];
    throw UsageError(flags + ": " + e.what());
  }
}

// Calibrate's own minimum (calibrate.h), checked here first so that the message can name the
// file and lines the view came from.
constexpr size_t kMinPointsPerView = 4;

// Each file's views: one per distinct value of its `view` column, or the whole file (named by its
// stem) without one. Pixels converted to kCenter. Throws InputError naming the file (and line) of
// a view with too few points, and both sources of a name given twice.
std::vector<CalibrationView> ReadViews(const std::vector<std::string>& paths, PixelOrigin origin) {
  std::vector<CalibrationView> views;
  std::map<std::string, std::string> source_of_name;
  for (const std::string& path : paths) {
    for (CorrespondencesView& file_view : ReadCorrespondencesViewsFile(path)) {
      const Correspondences& c = file_view.correspondences;
      const bool from_column = !file_view.name.empty();
      const std::string name =
          from_column ? file_view.name : std::filesystem::path(path).stem().string();
      const std::string source =
          from_column ? path + ", line " + std::to_string(c.line_numbers.front()) : path;
      if (c.pixels.size() < kMinPointsPerView) {
        throw InputError(source + ": view " + name + " has " + std::to_string(c.pixels.size()) +
                         " point" + (c.pixels.size() == 1 ? "" : "s") + "; a view needs at least " +
                         std::to_string(kMinPointsPerView));
      }
      const auto [it, inserted] = source_of_name.emplace(name, source);
      if (!inserted) {
        throw InputError(source + ": view name " + name + " is also the name of the view from " +
                         it->second + "; every view needs its own name");
      }
      CalibrationView view{name, c.points_in_world, {}, c.ids};
      view.pixels.reserve(c.pixels.size());
      for (const auto& pixel : c.pixels) {
        view.pixels.push_back(ConvertPixelOrigin(pixel, origin, PixelOrigin::kCenter));
      }
      views.push_back(std::move(view));
    }
  }
  return views;
}

// The summary's intrinsics (cx, cy in `origin`), and the criterion's choice per group.
void WriteIntrinsics(const Calibration& calibration, PixelOrigin origin, std::ostream& out) {
  const Intrinsics k = ConvertPixelOrigin(calibration.intrinsics, PixelOrigin::kCenter, origin);
  out << "intrinsics (pixel origin " << ToString(origin) << "):\n";
  for (const ParameterSigma& p : calibration.intrinsics_sigma) {
    double value = p.value;
    if (p.name == "cx") value = k.cx;
    if (p.name == "cy") value = k.cy;
    out << "  " << std::left << std::setw(5) << p.name << std::right << value << " +- " << p.sigma
        << (p.unit.empty() ? "" : " " + p.unit) << '\n';
  }
  out << "projection sigma: " << std::setprecision(3) << calibration.projection_sigma_center_px
      << " px at the image centre, " << calibration.projection_sigma_corner_px
      << " px at the worst image corner\n"
      << std::setprecision(6);
  if (!calibration.model_choice.empty()) {
    out << "model (BIC with sigma " << std::setprecision(3) << calibration.selection_sigma_px
        << " px, "
        << (calibration.selection_sigma_given ? "given" : "estimated from the richest model")
        << "):\n"
        << std::setprecision(6);
    for (const CalibrationModelChoice& c : calibration.model_choice) {
      out << "  " << std::left << std::setw(16) << c.group << std::right << c.reason << '\n';
    }
  }
}

// The points and views left out, each with why and the option that keeps it.
void WriteLeftOut(const Calibration& calibration, std::ostream& out) {
  for (const OutlierPoint& point : calibration.outliers) {
    out << "left out point " << point.id << " of " << point.view << ": " << std::setprecision(3)
        << point.residual_px << " px from the calibrated camera (bound " << point.bound_px
        << " px); --keep-all-points keeps it\n"
        << std::setprecision(6);
  }
  for (const RefusedView& view : calibration.refused_views) {
    if (!view.reason.empty()) {
      out << "refused view " << view.name << " (" << view.num_points << " points): " << view.reason
          << "; calibrated without it\n";
      continue;
    }
    out << "refused view " << view.name << ": its " << view.num_points << " points are "
        << std::setprecision(3) << view.rms_px << " px RMS from the camera the other views share ("
        << view.others_rms_px
        << " px): another camera, a blurred image or wrong "
           "correspondences; calibrated without it (--keep-all-views keeps it)\n"
        << std::setprecision(6);
  }
}

void WriteCrossValidation(const CrossValidation& cv, std::ostream& out) {
  if (!cv.done) {
    out << "cross-validation: not done: " << cv.why_not << '\n';
    return;
  }
  out << "cross-validation: the even and the odd views calibrated apart (" << cv.views_a << " and "
      << cv.views_b << ") put the image's pixels " << std::setprecision(3) << cv.rms_px
      << " px apart (RMS over a 16 x 12 grid; max " << cv.max_px
      << " px); their covariances predict " << cv.predicted_rms_px << " px";
  if (cv.rms_px > 3.0 * cv.predicted_rms_px) {
    out << ": more than 3 times that, so the views do not share one camera as this "
           "model describes it (a view that does not belong, or a lens that needs more "
           "than this model's terms)";
  }
  out << '\n' << std::setprecision(6);
}

// What `camproj calibrate` prints: the fit, the intrinsics, what was left out, the
// cross-validation, each view's RMS and the files written.
std::string CalibrationSummaryText(const Calibration& calibration, PixelOrigin origin,
                                   const CalibrateArgs& args) {
  std::ostringstream out;
  out << std::setprecision(6);
  out << "calibrated " << calibration.views.size() << " views, " << calibration.num_points
      << " points: rms " << calibration.rms_px << " px (" << calibration.iterations
      << " iterations)\n";
  WriteIntrinsics(calibration, origin, out);
  WriteLeftOut(calibration, out);
  WriteCrossValidation(calibration.cross_validation, out);
  out << "views (rms px):";
  for (const CalibratedView& view : calibration.views) {
    out << ' ' << view.name << ' ' << std::setprecision(3) << view.rms_px;
  }
  out << "\nwrote " << args.output_path;
  if (!args.poses_path.empty()) out << " and " << args.poses_path;
  out << '\n';
  return out.str();
}

int RunCalibrate(const CalibrateArgs& args) {
  CalibrateOptions options = ModelOptions(args.model, args.fix);
  options.image_size = ParseImageSize(args.image_size, "--image-size");
  options.pixel_sigma = args.sigma;
  options.refuse_inconsistent_views = !args.keep_all_views;
  options.remove_outliers = !args.keep_all_points;
  const PixelOrigin origin = PixelOriginFromString(args.pixel_origin);
  const std::vector<std::string> inputs = ExpandInputs(args.view_paths);
  RequireDistinctOptionOutputs({{"-o", args.output_path}, {"--poses", args.poses_path}});
  RequireOutputIsNotAnInput(args.output_path, inputs);
  if (!args.poses_path.empty()) RequireOutputIsNotAnInput(args.poses_path, inputs);

  const std::vector<CalibrationView> views = ReadViews(inputs, origin);
  const Calibration calibration = Calibrate(views, options);
  CameraFileOptions file_options;
  file_options.pixel_origin = origin;
  // Both files are made before either is written, and written as one: a failure leaves neither.
  const std::string calibration_text = CalibrationToJsonText(calibration, file_options);
  const std::string poses_text = CalibrationPosesCsvText(calibration, file_options);
  std::vector<OutputFile> outputs = {{args.output_path, calibration_text, "-o"}};
  if (!args.poses_path.empty()) outputs.push_back({args.poses_path, poses_text, "--poses"});
  WriteFilesAtomically(outputs);
  std::cout << TerminalSafe(CalibrationSummaryText(calibration, origin, args));
  return kExitOk;
}

void AddCalibrateOptions(CLI::App* app, CalibrateArgs* args) {
  app->add_option("VIEWS", args->view_paths,
                  "view CSV files (one view each, or several by a `view` column), or folders "
                  "of them")
      ->required();
  app->add_option("--image-size", args->image_size, "WxH in pixels")->required();
  app->add_option("-o,--output", args->output_path, "calibration file to write")->required();
  app->add_option("--poses", args->poses_path,
                  "also write a CSV of the views' poses: eye, target, up, R, t per view");
  app->add_option("--fix", args->fix,
                  "intrinsics --model auto never frees: aspect (fy = fx), principal-point (the "
                  "image centre), skew, k1 (and k2, k3), k2 (and k3), tangential, k3; "
                  "comma-separated")
      ->delimiter(',')
      ->check(CLI::IsMember({"aspect", "principal-point", "skew", "k1", "k2", "tangential", "k3"}));
  app->add_option("--model", args->model,
                  "auto (default): free only the groups the views need among those of opencv, "
                  "by BIC, from the focal length up (docs/calibration.md); opencv: cv::calibrateCamera's default model "
                  "(principal point, aspect, k1, k2, p1, p2, k3); or the groups to free joined "
                  "by '+' among principal-point, aspect, skew, k1, k2, tangential (p1, p2), k3, "
                  "e.g. principal-point+aspect+k1+k2 (calibrateCamera with "
                  "CALIB_ZERO_TANGENT_DIST | CALIB_FIX_K3)");
  app->add_option("--sigma", args->sigma,
                  "pixel noise (px, 1 sigma) for --model auto's criterion; default: estimated "
                  "from the richest model")
      ->check(PositiveFinite());
  app->add_flag("--keep-all-views", args->keep_all_views,
                "keep views that do not fit the camera the others share (by default such a view, "
                "more than 2.5x the others' RMS and beyond their noise, is left out and named)");
  app->add_flag("--keep-all-points", args->keep_all_points,
                "keep single points that do not fit (by default a point beyond the level-0.001 "
                "bound of the residuals' robust spread is left out and named)");
  app->add_option("--pixel-origin", args->pixel_origin,
                  "convention of the input pixels and the written cx, cy")
      ->check(CLI::IsMember({"center", "corner"}));
}

}  // namespace

Command AddCalibrateCommand(CLI::App& root) {
  auto args = std::make_shared<CalibrateArgs>();
  CLI::App* app = root.add_subcommand(
      "calibrate",
      "Calibrate one camera or projector from many views of known points (a chessboard moved in\n"
      "front of it, or a 3D rig): intrinsics shared by every view (the model the views need,\n"
      "chosen by BIC among OpenCV's fx, fy, cx, cy, k1, k2, p1, p2, k3), a pose per view, refined\n"
      "jointly (Ceres). Each view is a CSV with X,Y,Z,u,v in its own world frame (a board's frame\n"
      "is fine), named by its file name; a folder stands for its *.csv files. A CSV with a `view`\n"
      "column holds several views: its rows are grouped by that column's value, which names the\n"
      "view (ids may repeat across views, not within one). View names must be unique over all\n"
      "inputs. Writes CALIB.json: the intrinsics at the top level (so `camproj fit --intrinsics\n"
      "CALIB.json` fits poses against them) with their sigmas, and each view's full camera under\n"
      "views[i].camera (export and project take one by name: --view NAME).\n\n"
      "Example:\n"
      "  camproj calibrate data/real/opencv_chessboard/left*.csv --image-size 640x480 \\\n"
      "      -o left.json\n"
      "  camproj calibrate views.csv --image-size 640x480 -o calib.json  # view,X,Y,Z,u,v");
  AddCalibrateOptions(app, args.get());
  return {app, [args]() { return RunCalibrate(*args); }};
}

}  // namespace camproj::cli

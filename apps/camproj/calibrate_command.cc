// camproj calibrate: one camera from many views (shared intrinsics, a pose per view).
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>

#include "camproj/calibrate.h"
#include "camproj/calibration_file.h"
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
  bool skew = false;
  bool tangential = false;
  bool k3 = false;
  bool keep_all_views = false;
  std::string pixel_origin = "center";
};

}  // namespace

Command AddCalibrateCommand(CLI::App& root) {
  auto args = std::make_shared<CalibrateArgs>();
  CLI::App* app = root.add_subcommand(
      "calibrate",
      "Calibrate one camera or projector from many views of known points (a chessboard moved in\n"
      "front of it, or a 3D rig): intrinsics shared by every view (fx, fy, cx, cy, k1, k2 by\n"
      "default; p1, p2 with --tangential, k3 with --k3), a pose per view, refined jointly (Ceres). Each view is\n"
      "a CSV with X,Y,Z,u,v in its own world frame (a board's frame is fine); a folder stands for\n"
      "its *.csv files. Writes CALIB.json: the intrinsics at the top level (so `camproj fit\n"
      "--intrinsics CALIB.json` fits poses against them) with their sigmas, and each view's full\n"
      "camera under views[i].camera.\n\n"
      "Example:\n"
      "  camproj calibrate data/real/opencv_chessboard/left*.csv --image-size 640x480 -o left.json");
  app->add_option("VIEWS", args->view_paths, "view CSV files, or folders of them")->required();
  app->add_option("--image-size", args->image_size, "WxH in pixels")->required();
  app->add_option("-o,--output", args->output_path, "calibration file to write")->required();
  app->add_option("--poses", args->poses_path,
                  "also write a CSV of the views' poses: eye, target, up, R, t per view");
  app->add_option("--fix", args->fix,
                  "intrinsics to hold: aspect (fy = fx), principal-point (the image centre), k2, "
                  "k1 (and k2); comma-separated")
      ->delimiter(',')
      ->check(CLI::IsMember({"aspect", "principal-point", "k1", "k2"}));
  app->add_flag("--skew", args->skew, "also estimate skew (default 0)");
  app->add_flag("--tangential", args->tangential,
                "also estimate OpenCV's tangential distortion p1, p2 (default 0)");
  app->add_flag("--k3", args->k3, "also estimate the third radial term k3 (default 0); with "
                "--tangential, cv::calibrateCamera's default model");
  app->add_flag("--keep-all-views", args->keep_all_views,
                "keep views that do not fit the camera the others share (by default such a view, "
                "more than 2.5x the others' RMS and beyond their noise, is left out and named)");
  app->add_option("--pixel-origin", args->pixel_origin,
                  "convention of the input pixels and the written cx, cy")
      ->check(CLI::IsMember({"center", "corner"}));
  return {app, [args]() {
            CalibrateOptions options;
            options.image_size = ParseImageSize(args->image_size, "--image-size");
            for (const std::string& entry : args->fix) {
              if (entry == "aspect") options.aspect_free = false;
              if (entry == "principal-point") options.principal_point_free = false;
              if (entry == "k2") options.num_radial = std::min(options.num_radial, 1);
              if (entry == "k1") options.num_radial = 0;
            }
            options.skew_free = args->skew;
            options.tangential_free = args->tangential;
            if (args->k3) {
              if (options.num_radial < 2) {
                throw std::invalid_argument("--k3 needs k1 and k2 free: drop --fix k1/k2");
              }
              options.num_radial = 3;
            }
            options.refuse_inconsistent_views = !args->keep_all_views;
            const PixelOrigin origin = PixelOriginFromString(args->pixel_origin);
            const std::vector<std::string> inputs = ExpandInputs(args->view_paths);
            RequireOutputIsNotAnInput(args->output_path, inputs);
            if (!args->poses_path.empty()) RequireOutputIsNotAnInput(args->poses_path, inputs);

            std::vector<CalibrationView> views;
            for (const std::string& path : inputs) {
              const Correspondences file = ReadCorrespondencesFile(path);
              CalibrationView view{std::filesystem::path(path).stem().string(), file.points_in_world, {}};
              for (const auto& pixel : file.pixels) {
                view.pixels.push_back(ConvertPixelOrigin(pixel, origin, PixelOrigin::kCenter));
              }
              views.push_back(std::move(view));
            }
            const Calibration calibration = Calibrate(views, options);
            CameraFileOptions file_options;
            file_options.pixel_origin = origin;
            // Both files are made before either is written: a failure leaves neither.
            const std::string calibration_text = CalibrationToJsonText(calibration, file_options);
            const std::string poses_text = CalibrationPosesCsvText(calibration, file_options);
            WriteFileAtomically(args->output_path, calibration_text);
            if (!args->poses_path.empty()) WriteFileAtomically(args->poses_path, poses_text);

            const Intrinsics k = ConvertPixelOrigin(calibration.intrinsics, PixelOrigin::kCenter, origin);
            std::ostringstream out;
            out << std::setprecision(6);
            out << "calibrated " << calibration.views.size() << " views, " << calibration.num_points
                << " points: rms " << calibration.rms_px << " px (" << calibration.iterations
                << " iterations)\n";
            out << "intrinsics (pixel origin " << ToString(origin) << "):\n";
            for (const ParameterSigma& p : calibration.intrinsics_sigma) {
              double value = p.value;
              if (p.name == "cx") value = k.cx;
              if (p.name == "cy") value = k.cy;
              out << "  " << std::left << std::setw(5) << p.name << std::right << value << " +- "
                  << p.sigma << (p.unit.empty() ? "" : " " + p.unit) << '\n';
            }
            for (const RefusedView& view : calibration.refused_views) {
              out << "refused view " << view.name << ": its " << view.num_points << " points are "
                  << std::setprecision(3) << view.rms_px << " px RMS from the camera the other views share ("
                  << view.others_rms_px << " px): another camera, a blurred image or wrong "
                     "correspondences; calibrated without it (--keep-all-views keeps it)\n"
                  << std::setprecision(6);
            }
            const CrossValidation& cv = calibration.cross_validation;
            if (cv.done) {
              out << "cross-validation: the even and the odd views calibrated apart (" << cv.views_a
                  << " and " << cv.views_b << ") put the image's pixels " << std::setprecision(3)
                  << cv.rms_px << " px apart (RMS over a 16 x 12 grid; max " << cv.max_px
                  << " px); their covariances predict " << cv.predicted_rms_px << " px";
              if (cv.rms_px > 3.0 * cv.predicted_rms_px) {
                out << ": more than 3 times that, so the views do not share one camera as this "
                       "model describes it (a view that does not belong, or a lens that needs more "
                       "than this model's terms)";
              }
              out << '\n' << std::setprecision(6);
            } else {
              out << "cross-validation: not done: " << cv.why_not << '\n';
            }
            out << "views (rms px):";
            for (const CalibratedView& view : calibration.views) {
              out << ' ' << view.name << ' ' << std::setprecision(3) << view.rms_px;
            }
            out << "\nwrote " << args->output_path;
            if (!args->poses_path.empty()) out << " and " << args->poses_path;
            out << '\n';
            std::cout << TerminalSafe(out.str());
            return kExitOk;
          }};
}

}  // namespace camproj::cli

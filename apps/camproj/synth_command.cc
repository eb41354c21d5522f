// camproj synth: a reproducible synthetic scene and its true camera.
#include <charconv>
#include <cstdint>
#include <iostream>
#include <memory>

#include "camproj/camera_file.h"
#include "camproj/file_io.h"
#include "camproj/number_text.h"
#include "camproj/synth.h"
#include "cli.h"

namespace camproj::cli {

namespace {

struct SynthArgs {
  uint64_t seed = 1;
  int points = 20;
  double noise = 0.0;
  bool planar = false;
  std::string object = "cloud";
  double fovy_deg = 40.0;
  std::string principal_point_offset = "0,0";
  std::string image_size = "1920x1080";
  double aspect = 1.0;
  std::string output_path;
  std::string truth_path;
};

// A seed as written: digits only, within uint64_t (CLI11 converts "-1" to 2^64 - 1 and caps
// values beyond 2^64 - 1 there, so different seeds gave one scene).
const CLI::Validator& SeedText() {
  static const CLI::Validator validator(
      [](std::string& text) -> std::string {
        uint64_t value = 0;
        const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
        if (text.empty() || error != std::errc() || end != text.data() + text.size()) {
          return "must be a whole number from 0 to 18446744073709551615, got " + text;
        }
        return "";
      },
      "0..2^64-1");
  return validator;
}

}  // namespace

Command AddSynthCommand(CLI::App& root) {
  auto args = std::make_shared<SynthArgs>();
  CLI::App* app = root.add_subcommand(
      "synth",
      "Write a reproducible synthetic scene (points CSV) and its true camera.\n\n"
      "Example (a projector with lens shift to the bottom edge, points on a box):\n"
      "  camproj synth --seed 7 --points 20 --noise 1 --object box --principal-point-offset 0,0.5 \\\n"
      "      -o points.csv --truth truth.json");
  app->add_option("--seed", args->seed, "random seed")->check(SeedText());
  app->add_option("--points", args->points, "number of points")->check(CLI::Range(1, 100000000));
  app->add_option("--noise", args->noise, "pixel noise sigma per axis (px)")->check(NonNegativeFinite());
  CLI::Option* planar =
      app->add_flag("--planar", args->planar, "points on a plane (same as --object plane)");
  app->add_option("--object", args->object,
                  "cloud (in a box volume), box (on the faces the camera sees), plane")
      ->check(CLI::IsMember({"cloud", "box", "plane"}))
      // --object box --planar made a plane without a word.
      ->excludes(planar);
  app->add_option("--fovy", args->fovy_deg, "vertical field of view (degrees)")
      ->check(FiniteNumber());
  app->add_option("--principal-point-offset", args->principal_point_offset,
                  "DX,DY from the image centre as fractions of the image size (0,0.5: bottom edge)");
  app->add_option("--image-size", args->image_size, "WIDTHxHEIGHT");
  app->add_option("--aspect", args->aspect, "fy/fx of the true camera")->check(FiniteNumber());
  app->add_option("-o,--output", args->output_path, "points CSV to write")->required();
  app->add_option("--truth", args->truth_path, "true camera file to write")->required();
  return {app, [args]() {
            SynthOptions options;
            options.seed = args->seed;
            options.num_points = args->points;
            options.noise_px = args->noise;
            options.object = args->planar ? SynthObject::kPlane : SynthObjectFromString(args->object);
            options.fovy_deg = args->fovy_deg;
            const std::vector<double> offset =
                ParseNumbers(args->principal_point_offset, 2, "--principal-point-offset");
            options.principal_point_offset = {offset[0], offset[1]};
            options.image_size = ParseImageSize(args->image_size, "--image-size");
            options.aspect = args->aspect;
            try {
              options.Check();
            } catch (const std::invalid_argument& e) {
              throw UsageError(e.what());
            }
            RequireDistinctOptionOutputs({{"-o", args->output_path}, {"--truth", args->truth_path}});
            const SynthScene scene = SynthesizeScene(options);
            // The command that makes the scene again, every option spelled out (the defaults
            // may change; --planar is --object plane).
            const std::string csv =
                "# camproj synth --seed " + std::to_string(args->seed) + " --points " +
                std::to_string(args->points) + " --noise " + ShortestDouble(args->noise) +
                " --object " + (args->planar ? std::string("plane") : args->object) + " --fovy " +
                ShortestDouble(args->fovy_deg) + " --principal-point-offset " +
                ShortestDouble(offset[0]) + "," + ShortestDouble(offset[1]) + " --image-size " +
                std::to_string(options.image_size.width) + "x" +
                std::to_string(options.image_size.height) + " --aspect " +
                ShortestDouble(args->aspect) + " (pixels: OpenCV convention)\n" +
                CorrespondencesToCsvText(scene.correspondences);
            WriteFilesAtomically({{args->output_path, csv, "-o"},
                                  {args->truth_path, CameraToJsonText(scene.truth), "--truth"}});
            std::cout << "wrote " << args->output_path << " (" << args->points << " points) and "
                      << args->truth_path << "\n";
            return kExitOk;
          }};
}

}  // namespace camproj::cli

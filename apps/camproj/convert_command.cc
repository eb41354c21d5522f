// camproj convert: intrinsics <-> frustum <-> perspective <-> GL projection, on command-line values.
#include <iomanip>
#include <iostream>
#include <stdexcept>
#include <limits>
#include <memory>

#include "camproj/frustum.h"
#include "camproj/gl.h"
#include "cli.h"

namespace camproj::cli {

namespace {

struct ConvertArgs {
  std::string intrinsics;
  std::string frustum;
  std::string image_size;
  double skew = 0.0;
  double z_near = 0.0;
  double z_far = 0.0;
  std::string to;
  std::string depth = "no";
  bool reversed_z = false;
  std::string pixel_origin = "center";
};

// A value as printed: a zero without its sign ("bottom -0" for a frustum whose bottom edge is
// the principal point's row: -0 is +0 in every formula here).
double Shown(double value) { return value + 0.0; }

// The library refuses a matrix that is not finite (gl.h), so every entry prints as a number.
void PrintMatrix(const Eigen::Matrix4d& m) {
  std::cout << "projection (column-major)";
  for (int i = 0; i < 16; ++i) std::cout << ' ' << Shown(m.data()[i]);
  std::cout << '\n';
}

void PrintPerspective(const Perspective& p) {
  std::cout << "fovy_deg " << Shown(p.fovy_deg) << "\naspect " << Shown(p.aspect) << "\nnear "
            << Shown(p.z_near) << "\nfar " << Shown(p.z_far) << "\n";
}

}  // namespace

Command AddConvertCommand(CLI::App& root) {
  auto args = std::make_shared<ConvertArgs>();
  CLI::App* app = root.add_subcommand(
      "convert",
      "Convert between pinhole intrinsics, glFrustum, gluPerspective and the GL projection\n"
      "matrix for an image size (formulas: docs/conventions.md).\n\n"
      "Examples:\n"
      "  camproj convert --intrinsics 1000,1000,959.5,539.5 --image-size 1920x1080 --near 0.1 --far 100 --to frustum\n"
      "  camproj convert --intrinsics 1000,1000,959.5,539.5 --image-size 1920x1080 --near 0.1 --far 100 --to gl --depth zo\n"
      "  camproj convert --frustum -0.096,0.096,-0.054,0.054,0.1,100 --image-size 1920x1080 --to intrinsics");
  auto* from = app->add_option_group("from", "the input: one of");
  from->add_option("--intrinsics", args->intrinsics, "fx,fy,cx,cy (px)");
  from->add_option("--frustum", args->frustum, "left,right,bottom,top,near,far as glFrustum");
  from->require_option(1);
  app->add_option("--image-size", args->image_size, "WIDTHxHEIGHT")->required();
  app->add_option("--skew", args->skew, "skew (px) with --intrinsics (only --to gl can carry it)")
      ->check(FiniteNumber());
  app->add_option("--near", args->z_near, "near plane distance (with --intrinsics)")
      ->check(FiniteNumber());
  app->add_option("--far", args->z_far, "far plane distance (with --intrinsics)")
      ->check(FiniteNumber());
  app->add_option("--to", args->to, "output")
      ->required()->check(CLI::IsMember({"frustum", "perspective", "gl", "intrinsics"}));
  CLI::Option* depth = app->add_option("--depth", args->depth, "gl: no = [-1,1], zo = [0,1]")
                           ->check(CLI::IsMember({"no", "zo"}));
  CLI::Option* reversed_z = app->add_flag("--reversed-z", args->reversed_z, "gl: reversed-Z");
  CLI::Option* pixel_origin =
      app->add_option("--pixel-origin", args->pixel_origin, "convention of cx, cy")
          ->check(CLI::IsMember({"center", "corner"}));
  return {app, [args, depth, reversed_z, pixel_origin]() {
            // Options the conversion asked for would not read are refused, not dropped.
            if (args->to != "gl" && (depth->count() > 0 || reversed_z->count() > 0)) {
              throw UsageError("--depth and --reversed-z go with --to gl");
            }
            if (pixel_origin->count() > 0 && !args->frustum.empty() && args->to != "intrinsics") {
              throw UsageError("--pixel-origin is the convention of cx, cy: it goes with "
                               "--intrinsics or --to intrinsics");
            }
            const ImageSize size = ParseImageSize(args->image_size, "--image-size");
            const PixelOrigin origin = PixelOriginFromString(args->pixel_origin);
            std::cout << std::setprecision(std::numeric_limits<double>::max_digits10);
            if (!args->frustum.empty()) {
              const std::vector<double> f = ParseNumbers(args->frustum, 6, "--frustum");
              const Frustum frustum{f[0], f[1], f[2], f[3], f[4], f[5]};
              try {
                frustum.Check();
              } catch (const std::invalid_argument& e) {
                throw UsageError(std::string("--frustum: ") + e.what());
              }
              if (args->to != "intrinsics" && args->to != "gl" && args->to != "perspective") {
                throw UsageError("--frustum converts --to intrinsics, perspective or gl");
              }
              if (args->skew != 0.0 || args->z_near != 0.0 || args->z_far != 0.0) {
                throw UsageError("--skew, --near and --far go with --intrinsics: a frustum has "
                                 "its own near and far, and no skew");
              }
              if (args->to == "intrinsics") {
                const Intrinsics k = IntrinsicsFromFrustum(frustum, size, origin);
                std::cout << "fx " << Shown(k.fx) << "\nfy " << Shown(k.fy) << "\ncx "
                          << Shown(k.cx) << "\ncy " << Shown(k.cy) << "\n";
              } else if (args->to == "perspective") {
                PrintPerspective(PerspectiveFromFrustum(frustum));
              } else {
                PrintMatrix(ClipFromGlEye(frustum, {ClipDepthFromString(args->depth), args->reversed_z}));
              }
              return kExitOk;
            }
            const std::vector<double> v = ParseNumbers(args->intrinsics, 4, "--intrinsics");
            Intrinsics k;
            k.fx = v[0];
            k.fy = v[1];
            k.cx = v[2];
            k.cy = v[3];
            k.skew = args->skew;
            try {
              k.Check();
            } catch (const std::invalid_argument& e) {
              throw UsageError(std::string("--intrinsics: ") + e.what());
            }
            if (args->to == "intrinsics") throw UsageError("--intrinsics converts --to frustum, perspective or gl");
            if (!(args->z_near > 0.0) || !(args->z_far > args->z_near)) {
              throw UsageError("--near and --far are needed, with 0 < near < far");
            }
            if (args->to == "frustum") {
              const Frustum f = FrustumFromIntrinsics(k, size, args->z_near, args->z_far, origin);
              std::cout << "left " << Shown(f.left) << "\nright " << Shown(f.right) << "\nbottom "
                        << Shown(f.bottom) << "\ntop " << Shown(f.top) << "\nnear "
                        << Shown(f.z_near) << "\nfar " << Shown(f.z_far) << "\n";
            } else if (args->to == "perspective") {
              PrintPerspective(PerspectiveFromIntrinsics(k, size, args->z_near, args->z_far, origin));
            } else {
              PrintMatrix(ClipFromGlEye(k, size, args->z_near, args->z_far,
                                        {ClipDepthFromString(args->depth), args->reversed_z}, origin));
            }
            return kExitOk;
          }};
}

}  // namespace camproj::cli

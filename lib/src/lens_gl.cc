#include "camproj/lens_gl.h"

#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <cmath>
#include <iomanip>
#include <limits>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <sstream>

#include "camproj/world_origin.h"
#include "check.h"
#include "exact_stream.h"
#include "image_codecs.h"

namespace camproj {

namespace {

using internal::Concat;
using internal::Require;
using ordered_json = nlohmann::ordered_json;

double DistortedRadius(double r, double k1, double k2) {
  const double r2 = r * r;
  return r * (1.0 + r2 * (k1 + r2 * k2));
}

std::array<Eigen::Vector2d, 4> OuterCorners(const ImageSize& size) {
  const double w = size.width;
  const double h = size.height;
  return {Eigen::Vector2d(-0.5, -0.5), Eigen::Vector2d(w - 0.5, -0.5),
          Eigen::Vector2d(-0.5, h - 0.5), Eigen::Vector2d(w - 0.5, h - 0.5)};
}

// Distorted normalized coordinates of a pixel: K^-1 without the radial part.
Eigen::Vector2d DistortedNormalized(const Intrinsics& k, const Eigen::Vector2d& pixel) {
  const double yd = (pixel.y() - k.cy) / k.fy;
  return {(pixel.x() - k.cx - k.skew * yd) / k.fx, yd};
}

// Pixel (of the render target) of normalized coordinates under a pinhole.
Eigen::Vector2d PinholePixel(const Intrinsics& k, const Eigen::Vector2d& n) {
  return {k.fx * n.x() + k.skew * n.y() + k.cx, k.fy * n.y() + k.cy};
}

Eigen::Vector2d PinholeNormalized(const Intrinsics& k, const Eigen::Vector2d& pixel) {
  return DistortedNormalized(k, pixel);  // the same K^-1
}

// The camera's (distorted) pixel of normalized coordinates n.
Eigen::Vector2d LensPixel(const Intrinsics& k, const Eigen::Vector2d& n) {
  const std::array<double, kIntrinsicsArraySize> params = IntrinsicsArray(k);
  Eigen::Vector2d pixel;
  PixelFromNormalized(params.data(), n.x(), n.y(), pixel.data());
  return pixel;
}

// Undistorted normalized coordinates of a camera pixel inside the fold.
Eigen::Vector2d UndistortedNormalized(const Intrinsics& k, const Eigen::Vector2d& pixel) {
  return CamRayFromPixel(k, pixel).head<2>();
}

// Nuke STMap / GL texture coordinates of a kCenter pixel in an image of `size`: window / size.
Eigen::Vector2d UvOfPixel(const Eigen::Vector2d& pixel, const ImageSize& size) {
  return {(pixel.x() + 0.5) / size.width, 1.0 - (pixel.y() + 0.5) / size.height};
}

using internal::ExactStream;

// A GLSL float literal that reads back to the same float as the double rounds to. Throws for a
// value beyond float32's range (a literal above 3.4e38 is infinite in GLSL), naming it.
std::string GlslFloat(double value, const char* name) {
  Require(std::abs(value) <= std::numeric_limits<float>::max(), "GLSL constant ", name,
          " = ", value, " is beyond float32's range (", std::numeric_limits<float>::max(), ")");
  auto out = ExactStream();
  out << value;
  std::string text = out.str();
  if (text.find_first_of(".e") == std::string::npos) text += ".0";
  return text;
}

std::string GlslMat4(const Eigen::Matrix4d& m, const char* name) {
  std::string text = "mat4(";
  for (int i = 0; i < 16; ++i) {
    text += (i ? ", " : "") + GlslFloat(m.data()[i], name);  // column-major
  }
  return text + ")";
}

std::string Short(double value) {
  std::ostringstream out;
  out << std::setprecision(3) << value;
  return out.str();
}

ordered_json Matrix4Json(const Eigen::Matrix4d& m) {
  ordered_json numbers = ordered_json::array();
  for (int i = 0; i < 16; ++i) numbers.push_back(m.data()[i]);  // column-major
  return numbers;
}

}  // namespace

void RequireLensCoversImage(const Camera& camera) {
  camera.Check();
  Require(camera.projection == Projection::kPerspective,
          "an orthographic camera has no lens distortion to render");
  const Intrinsics& k = camera.intrinsics;
  Require(!k.HasBeyondTwoRadial(), "the GL lens renders radial k1, k2 only; this camera also has "
          "p1 = ", k.p1, ", p2 = ", k.p2, ", k3 = ", k.k3, " (calibrate with --fix tangential,k3 "
          "or a --model without tangential and k3 for a lens GL can render, or warp with "
          "OpenCV's cv::remap from the opencv-yaml export)");
  for (const Eigen::Vector2d& corner : OuterCorners(camera.image_size)) {
    const double rd = DistortedNormalized(k, corner).stableNorm();
    Require(rd < kLensMaxNormalizedRadius, "the image corner (", corner.x(), ", ", corner.y(),
            ") is at normalized radius ", rd, " (fx = ", k.fx, ", fy = ", k.fy,
            "): the image spans 180 degrees to within a double, which no lens rendering or "
            "render target can hold");
  }
  const double r_fold = RadialFoldRadius(k.k1, k.k2);
  if (!std::isfinite(r_fold)) return;
  const double rd_fold = DistortedRadius(r_fold, k.k1, k.k2);
  for (const Eigen::Vector2d& corner : OuterCorners(camera.image_size)) {
    const double rd = DistortedNormalized(k, corner).norm();
    Require(rd < rd_fold, "the lens model does not cover the image: radial distortion k1 = ", k.k1,
            ", k2 = ", k.k2, " folds over at normalized radius ", r_fold, " (distorted ", rd_fold,
            "), but the image corner (", corner.x(), ", ", corner.y(), ") is at distorted radius ",
            rd, "; no lens rendering can reproduce it");
  }
}

double LensImageRadius(const Camera& camera) {
  RequireLensCoversImage(camera);
  double radius = 0.0;
  for (const Eigen::Vector2d& corner : OuterCorners(camera.image_size)) {
    radius = std::max(radius, UndistortedNormalized(camera.intrinsics, corner).norm());
  }
  return radius;
}

double LensRadiusLimit(const Camera& camera) {
  const double image_radius = LensImageRadius(camera);
  return std::min(RadialFoldRadius(camera.intrinsics.k1, camera.intrinsics.k2), 2.0 * image_radius);
}

LensRenderTarget LensRenderTargetOf(const Camera& camera) {
  RequireLensCoversImage(camera);
  const Intrinsics& k = camera.intrinsics;
  const Intrinsics pinhole = k.Pinhole();
  // The preimage of the image is bounded by the preimage of its outer edges (the lens is a
  // homeomorphism inside the fold), sampled every 1/4 px.
  const double w = camera.image_size.width;
  const double h = camera.image_size.height;
  constexpr int kSamplesPerPx = 4;
  Eigen::Vector2d low = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector2d high = -low;
  const auto visit = [&](double u, double v) {
    const Eigen::Vector2d q = PinholePixel(pinhole, UndistortedNormalized(k, {u, v}));
    low = low.cwiseMin(q);
    high = high.cwiseMax(q);
  };
  const int steps_u = camera.image_size.width * kSamplesPerPx;
  const int steps_v = camera.image_size.height * kSamplesPerPx;
  for (int i = 0; i <= steps_u; ++i) {
    const double u = -0.5 + w * i / steps_u;
    visit(u, -0.5);
    visit(u, h - 0.5);
  }
  for (int i = 0; i <= steps_v; ++i) {
    const double v = -0.5 + h * i / steps_v;
    visit(-0.5, v);
    visit(w - 0.5, v);
  }
  // Target pixel q + offset must keep kLensRenderTargetMarginPx from the centres of the first
  // and last texels (0 and size - 1).
  const double offset_x = std::ceil(kLensRenderTargetMarginPx - low.x());
  const double offset_y = std::ceil(kLensRenderTargetMarginPx - low.y());
  const double width = std::ceil(high.x() + offset_x + kLensRenderTargetMarginPx) + 1.0;
  const double height = std::ceil(high.y() + offset_y + kLensRenderTargetMarginPx) + 1.0;
  // Checked in double before any conversion to int (offsets beyond the side limit only occur
  // with a side beyond it too: the image's own footprint lies inside the target).
  Require(width <= kLensRenderTargetMaxSidePx && height <= kLensRenderTargetMaxSidePx &&
              std::abs(offset_x) <= kLensRenderTargetMaxSidePx &&
              std::abs(offset_y) <= kLensRenderTargetMaxSidePx,
          "the lens's render target would be ", width, " x ", height, " px (k1 = ", k.k1,
          ", k2 = ", k.k2, "), more than ", kLensRenderTargetMaxSidePx, " px a side");
  LensRenderTarget target;
  target.offset_x = static_cast<int>(offset_x);
  target.offset_y = static_cast<int>(offset_y);
  target.size = {static_cast<int>(width), static_cast<int>(height)};
  target.intrinsics = pinhole;
  target.intrinsics.cx += target.offset_x;
  target.intrinsics.cy += target.offset_y;
  return target;
}

Eigen::Matrix4d LensRenderTargetClipFromGlEye(const Camera& camera, const GlDepth& depth) {
  const LensRenderTarget target = LensRenderTargetOf(camera);
  return ClipFromGlEye(target.intrinsics, target.size, camera.z_near, camera.z_far, depth);
}

double LensSecondDerivativePx(const Camera& camera) {
  const LensRenderTarget target = LensRenderTargetOf(camera);
  const Intrinsics& k = camera.intrinsics;
  if (!k.HasDistortion()) return 0.0;
  // D(p) = A F(A^-1 (p - c)) + c with A = [fx skew; 0 fy] and F(n) = n d(|n|^2), so
  // D''[t, t] = A F''[a, a] with a = A^-1 t, and (differentiating F(n + e a) twice in e) the
  // symmetric bilinear form F''[a, b] = 2 d' ((n.a) b + (n.b) a) + n (4 d'' (n.a)(n.b) + 2 d' a.b),
  // d' = k1 + 2 k2 s, d'' = 2 k2. With t = (cos, sin), D''[t, t] = cos^2 G11 + 2 cos sin G12 +
  // sin^2 G22, G_ij = A F''[b_i, b_j], b_i = A^-1 e_i: three evaluations per point.
  Eigen::Matrix2d a_matrix;
  a_matrix << k.fx, k.skew, 0.0, k.fy;
  const Eigen::Matrix2d b = a_matrix.inverse();
  constexpr int kDirections = 64;
  std::array<Eigen::Vector3d, kDirections> weights;  // cos^2, 2 cos sin, sin^2
  for (int i = 0; i < kDirections; ++i) {
    const double angle = M_PI * i / kDirections;
    const double c = std::cos(angle);
    const double sn = std::sin(angle);
    weights[i] = Eigen::Vector3d(c * c, 2.0 * c * sn, sn * sn);
  }
  const auto second_derivative = [&](const Eigen::Vector2d& n) {
    const double s = n.squaredNorm();
    const double d1 = k.k1 + 2.0 * k.k2 * s;
    const double d2 = 2.0 * k.k2;
    const auto form = [&](const Eigen::Vector2d& a, const Eigen::Vector2d& c) -> Eigen::Vector2d {
      const double na = n.dot(a);
      const double nc = n.dot(c);
      return a_matrix *
             (2.0 * d1 * (na * c + nc * a) + n * (4.0 * d2 * na * nc + 2.0 * d1 * a.dot(c)));
    };
    const Eigen::Vector2d g11 = form(b.col(0), b.col(0));
    const Eigen::Vector2d g12 = form(b.col(0), b.col(1));
    const Eigen::Vector2d g22 = form(b.col(1), b.col(1));
    double worst = 0.0;
    for (const Eigen::Vector3d& w : weights) {
      worst = std::max(worst, (w.x() * g11 + w.y() * g12 + w.z() * g22).squaredNorm());
    }
    return std::sqrt(worst);
  };
  // The footprint: the preimage of the image's outer edges (every px), and the render target
  // pixels whose lens pixel lies in the image, every `stride`-th so that at most ~250 000 are
  // visited (the second derivative varies on the scale of the image, not of a pixel).
  const double w = camera.image_size.width;
  const double h = camera.image_size.height;
  double worst = 0.0;
  const auto edge = [&](double u, double v) {
    worst = std::max(worst, second_derivative(UndistortedNormalized(k, {u, v})));
  };
  for (int i = 0; i <= camera.image_size.width; ++i) {
    edge(i - 0.5, -0.5);
    edge(i - 0.5, h - 0.5);
  }
  for (int i = 0; i <= camera.image_size.height; ++i) {
    edge(-0.5, i - 0.5);
    edge(w - 0.5, i - 0.5);
  }
  const double r_fold = RadialFoldRadius(k.k1, k.k2);
  const int stride = std::max(
      1, static_cast<int>(std::sqrt(1.0 * target.size.width * target.size.height / 250000.0)));
  for (int y = 0; y < target.size.height; y += stride) {
    for (int x = 0; x < target.size.width; x += stride) {
      const Eigen::Vector2d n = PinholeNormalized(target.intrinsics, {x, y});
      if (!(n.norm() < r_fold)) continue;
      const Eigen::Vector2d p = LensPixel(k, n);
      if (p.x() < -0.5 || p.x() > w - 0.5 || p.y() < -0.5 || p.y() > h - 0.5) continue;
      worst = std::max(worst, second_derivative(n));
    }
  }
  return worst;
}

double LensMaxEdgePx(const Camera& camera, double error_px) {
  Require(error_px > 0.0 && std::isfinite(error_px), "error_px must be positive, got ", error_px);
  const double m = LensSecondDerivativePx(camera);
  if (m == 0.0) return std::numeric_limits<double>::infinity();
  return std::sqrt(6.0 * error_px / m);
}

std::string LensGlslText(const Camera& camera, const GlDepth& depth) {
  const double r_limit = LensRadiusLimit(camera);
  // The coefficients first: a lens float32 cannot hold is refused as that, whatever follows.
  const std::string k1_text = GlslFloat(camera.intrinsics.k1, "k1");
  const std::string k2_text = GlslFloat(camera.intrinsics.k2, "k2");
  const double m = LensSecondDerivativePx(camera);
  Require(std::isfinite(m), "the lens map's second derivative over the image is beyond a double "
          "(k1 = ", camera.intrinsics.k1, ", k2 = ", camera.intrinsics.k2,
          "): no tessellation bounds the per-vertex error");
  // With a lens, r_limit^2 below float32's smallest normal would flush to 0 and leave every
  // vertex undistorted (without one camproj_lens is the identity whatever the limit).
  Require(m == 0.0 || r_limit * r_limit >= std::numeric_limits<float>::min(),
          "the lens's radius limit squared ", r_limit * r_limit,
          " is below float32's smallest normal number");
  const auto max_edge = [m](double error_px) {
    return m == 0.0 ? std::numeric_limits<double>::infinity() : std::sqrt(6.0 * error_px / m);
  };
  const Intrinsics& k = camera.intrinsics;
  const double r_fold = RadialFoldRadius(k.k1, k.k2);
  const CameraViews views = ViewsOfCamera(camera, 1.0, depth);
  auto out = ExactStream();
  out << "// camproj GLSL lens export (docs/exports.md, section glsl): radial distortion k1 = "
      << k.k1 << ", k2 = " << k.k2 << "\n"
      << "// applied per vertex in gl_eye, before the pinhole projection matrix. GLSL 1.30+ / ES "
         "3.00.\n"
      << "//   gl_Position = camproj_projection * camproj_lens(camproj_view * vec4(world_position, "
         "1.0));\n"
      << "// Image " << camera.image_size.width << " x " << camera.image_size.height
      << ": glViewport(0, 0, " << camera.image_size.width << ", " << camera.image_size.height
      << "); pixels: GL window x = u + 0.5, y = " << camera.image_size.height
      << " - (v + 0.5) for the camproj kCenter pixel (u, v).\n"
      << "// Depth " << ToString(depth.clip_depth) << (depth.reversed_z ? ", reversed-Z" : "")
      << "; near " << camera.z_near << ", far " << camera.z_far
      << ": camproj_lens leaves z and w alone, so depth is as in the gl export.\n"
      << "// " << WorldOriginNote(camera) << ".\n";
  if (m == 0.0) {
    out << "// k1 = k2 = 0: camproj_lens is the identity (the matrices are the whole camera).\n";
  } else {
    out << "// Exact at vertices (float32: ~1e-5 px); between them GL interpolates linearly, so "
           "tessellate: keep\n"
        << "// the longest edge of every triangle, in px on the undistorted image, below "
        << Short(max_edge(0.1)) << " px for 0.1 px, " << Short(max_edge(0.01))
        << " px for 0.01 px, " << Short(max_edge(0.001)) << " px for 0.001 px\n"
        << "// (M L^2 / 6 <= error, M = " << Short(m)
        << " px^-1, the largest second derivative of the lens map over the image).\n";
  }
  out << "// "
      << (std::isfinite(r_fold)
              ? Concat("The model folds over at normalized radius ", Short(r_fold), "; ")
              : std::string("The model has no fold; "))
      << "beyond r_limit = " << Short(r_limit)
      << " (outside the image) the radial scale d is held at d(r_limit),\n"
      << "// so geometry there keeps moving outwards and never folds back into the image. Vertices "
         "at or\n"
      << "// behind the eye plane (z_eye >= 0; eye.w > 0 assumed) are left alone: the near plane "
         "clips them.\n";
  out << "const float camproj_k1 = " << k1_text << ";\n"
      << "const float camproj_k2 = " << k2_text << ";\n"
      << "const float camproj_r2_limit = " << GlslFloat(r_limit * r_limit, "r_limit^2") << ";\n"
      << "const mat4 camproj_projection = "
      << GlslMat4(views.clip_from_gl_eye, "a projection matrix entry") << ";\n"
      << "const mat4 camproj_view = "
      << GlslMat4(views.gl_eye_from_origin_world, "a view matrix entry") << ";\n"
      << "// gl_eye (x right, y up, looking down -z) is cam (x right, y down, z forward) with y "
         "and\n"
      << "// z negated: x = X/Z = x_eye / -z_eye, y = Y/Z = y_eye / z_eye. Only r^2 = x^2 + y^2 "
         "is\n"
      << "// needed, and distorting (x, y) by d is scaling eye.xy by d: the x, y rows of the "
         "projection\n"
      << "// matrix are linear in eye.xy (skew too), its z and w rows see only eye.zw.\n"
      << "vec4 camproj_lens(vec4 eye) {\n"
      << "  if (eye.z >= 0.0) return eye;\n"
      << "  vec2 n = eye.xy / -eye.z;\n"
      << "  float r2 = min(dot(n, n), camproj_r2_limit);\n"
      << "  float d = 1.0 + r2 * (camproj_k1 + r2 * camproj_k2);\n"
      << "  return vec4(d * eye.xy, eye.zw);\n"
      << "}\n";
  return out.str();
}

StMap LensStMap(const Camera& camera, LensMapDirection direction) {
  const LensRenderTarget target = LensRenderTargetOf(camera);
  const Intrinsics& k = camera.intrinsics;
  StMap map;
  if (direction == LensMapDirection::kDistort) {
    map.width = camera.image_size.width;
    map.height = camera.image_size.height;
    map.rgba.resize(static_cast<size_t>(map.width) * map.height * 4);
    for (int v = 0; v < map.height; ++v) {
      for (int u = 0; u < map.width; ++u) {
        const Eigen::Vector2d source =
            PinholePixel(target.intrinsics, UndistortedNormalized(k, {u, v}));
        const Eigen::Vector2d uv = UvOfPixel(source, target.size);
        float* texel = &map.rgba[(static_cast<size_t>(v) * map.width + u) * 4];
        texel[0] = static_cast<float>(uv.x());
        texel[1] = static_cast<float>(uv.y());
        texel[2] = 0.0f;
        texel[3] = 1.0f;
      }
    }
    return map;
  }
  map.width = target.size.width;
  map.height = target.size.height;
  map.rgba.resize(static_cast<size_t>(map.width) * map.height * 4);
  const double r_fold = RadialFoldRadius(k.k1, k.k2);
  for (int v = 0; v < map.height; ++v) {
    for (int u = 0; u < map.width; ++u) {
      float* texel = &map.rgba[(static_cast<size_t>(v) * map.width + u) * 4];
      const Eigen::Vector2d n = PinholeNormalized(target.intrinsics, {u, v});
      texel[2] = 0.0f;
      if (!(n.norm() < r_fold)) {
        texel[0] = texel[1] = -1.0f;
        texel[3] = 0.0f;
        continue;
      }
      const Eigen::Vector2d source = LensPixel(k, n);
      const Eigen::Vector2d uv = UvOfPixel(source, camera.image_size);
      texel[0] = static_cast<float>(uv.x());
      texel[1] = static_cast<float>(uv.y());
      texel[3] = PixelInImage(source, camera.image_size) ? 1.0f : 0.0f;
    }
  }
  return map;
}

std::string EncodeStMap(const StMap& map, const std::string& extension) {
  Require(extension == ".tif" || extension == ".tiff" || extension == ".exr",
          "an STMap is written as .tif, .tiff or .exr (32-bit float RGBA), got \"", extension,
          "\"");
  Require(map.width > 0 && map.height > 0 &&
              map.rgba.size() == static_cast<size_t>(map.width) * map.height * 4,
          "STMap of ", map.width, " x ", map.height, " px holds ", map.rgba.size(),
          " floats, not 4 per pixel");
  // OpenCV stores 4 channels as B, G, R, A and writes them to the file as R, G, B, A.
  cv::Mat image(map.height, map.width, CV_32FC4);
  for (int y = 0; y < map.height; ++y) {
    for (int x = 0; x < map.width; ++x) {
      const float* texel = &map.rgba[(static_cast<size_t>(y) * map.width + x) * 4];
      image.at<cv::Vec4f>(y, x) = cv::Vec4f(texel[2], texel[1], texel[0], texel[3]);
    }
  }
  std::vector<uchar> bytes;
  Require(internal::EncodeImage(extension == ".exr" ? ".exr" : ".tiff", image, &bytes),
          "OpenCV could not encode the STMap as ", extension);
  return std::string(bytes.begin(), bytes.end());
}

namespace {

// The distortion mesh: per vertex, render target (kCenter) source pixel and output window
// coordinates; three vertex indices per triangle.
struct LensMesh {
  std::vector<Eigen::Vector2d> source;
  std::vector<Eigen::Vector2d> window;
  std::vector<int> triangles;
};

// The lens's pixel of normalized coordinates n with the GLSL function's rule: beyond r_limit the
// radial scale stays d(r_limit).
Eigen::Vector2d LimitedLensPixel(const Intrinsics& k, const Eigen::Vector2d& n, double r_limit) {
  const double r = n.norm();
  if (!(r > r_limit)) return LensPixel(k, n);
  const double s = r_limit * r_limit;
  const double d = 1.0 + s * (k.k1 + s * k.k2);
  return PinholePixel(k, d * n);
}

// A grid over the render target (where the forward lens is a polynomial, smooth up to the fold),
// vertices every step_px of its window coordinates, edges included; each vertex's output is the
// lens's pixel of its source, as the GLSL function computes it.
LensMesh BuildLensMesh(const Camera& camera, const LensRenderTarget& target, int step_px) {
  Require(step_px >= 1, "the mesh step must be at least 1 px, got ", step_px);
  const Intrinsics& k = camera.intrinsics;
  const double r_limit = LensRadiusLimit(camera);
  const auto lines = [step_px](int size) {
    std::vector<int> values;
    for (int x = 0; x < size; x += step_px) values.push_back(x);
    values.push_back(size);
    return values;
  };
  const std::vector<int> xs = lines(target.size.width);
  const std::vector<int> ys = lines(target.size.height);
  const int columns = static_cast<int>(xs.size());
  LensMesh mesh;
  for (const int y : ys) {
    for (const int x : xs) {
      const Eigen::Vector2d source(x - 0.5, target.size.height - y - 0.5);
      mesh.source.push_back(source);
      const Eigen::Vector2d output =
          LimitedLensPixel(k, PinholeNormalized(target.intrinsics, source), r_limit);
      mesh.window.emplace_back(output.x() + 0.5, camera.image_size.height - output.y() - 0.5);
    }
  }
  for (int row = 0; row + 1 < static_cast<int>(ys.size()); ++row) {
    for (int column = 0; column + 1 < columns; ++column) {
      const int a = row * columns + column;  // bottom-left in window coordinates
      const int b = a + 1;
      const int c = a + columns + 1;
      const int d = a + columns;
      mesh.triangles.insert(mesh.triangles.end(), {a, b, c, a, c, d});
    }
  }
  return mesh;
}

// The interpolation error (output px): at the barycentric points (i, j, l) / 4 other than the
// vertices of every triangle, how far the lens images the interpolated source point from the
// interpolated output point where the GL draws it, for the points drawn inside the image.
double LensMeshErrorPx(const Camera& camera, const LensRenderTarget& target, const LensMesh& mesh) {
  const double w = camera.image_size.width;
  const double h = camera.image_size.height;
  const double r_fold = RadialFoldRadius(camera.intrinsics.k1, camera.intrinsics.k2);
  double worst = 0.0;
  for (size_t t = 0; t < mesh.triangles.size(); t += 3) {
    for (int i = 0; i <= 4; ++i) {
      for (int j = 0; i + j <= 4; ++j) {
        const int l = 4 - i - j;
        if (i == 4 || j == 4 || l == 4) continue;
        const auto mix = [&](const std::vector<Eigen::Vector2d>& points) {
          return (i * points[mesh.triangles[t]] + j * points[mesh.triangles[t + 1]] +
                  l * points[mesh.triangles[t + 2]]) /
                 4.0;
        };
        const Eigen::Vector2d window = mix(mesh.window);
        if (window.x() < 0.0 || window.x() > w || window.y() < 0.0 || window.y() > h) continue;
        const Eigen::Vector2d drawn(window.x() - 0.5, h - window.y() - 0.5);
        const Eigen::Vector2d n = PinholeNormalized(target.intrinsics, mix(mesh.source));
        // Beyond the fold the lens images nothing there: the drawn point is wrong by far.
        const double error = n.norm() < r_fold ? (LensPixel(camera.intrinsics, n) - drawn).norm()
                                               : std::numeric_limits<double>::infinity();
        worst = std::max(worst, error);
      }
    }
  }
  return worst;
}

}  // namespace

int LensMeshStepPx(const Camera& camera, double error_px) {
  Require(error_px > 0.0 && std::isfinite(error_px), "error_px must be positive, got ", error_px);
  const LensRenderTarget target = LensRenderTargetOf(camera);
  for (int step = kLensMeshMaxStepPx; step > 1; step /= 2) {
    if (LensMeshErrorPx(camera, target, BuildLensMesh(camera, target, step)) <= error_px) {
      return step;
    }
  }
  return 1;
}

std::string LensDistortionMeshJson(const Camera& camera, int step_px, const GlDepth& depth) {
  const LensRenderTarget target = LensRenderTargetOf(camera);
  if (step_px == 0) step_px = LensMeshStepPx(camera, kLensMeshErrorPx);
  const LensMesh mesh = BuildLensMesh(camera, target, step_px);
  const double worst = LensMeshErrorPx(camera, target, mesh);
  const std::vector<Eigen::Vector2d>& window = mesh.window;
  const std::vector<Eigen::Vector2d>& source = mesh.source;
  const std::vector<int>& triangles = mesh.triangles;
  const int w = camera.image_size.width;
  const int h = camera.image_size.height;
  ordered_json distorted_uv = ordered_json::array();
  ordered_json undistorted_uv = ordered_json::array();
  for (size_t i = 0; i < window.size(); ++i) {
    distorted_uv.push_back(window[i].x() / w);
    distorted_uv.push_back(window[i].y() / h);
    const Eigen::Vector2d uv = UvOfPixel(source[i], target.size);
    undistorted_uv.push_back(uv.x());
    undistorted_uv.push_back(uv.y());
  }
  const Eigen::Matrix4d projection =
      ClipFromGlEye(target.intrinsics, target.size, camera.z_near, camera.z_far, depth);
  ordered_json document;
  document["format"] = "camproj distortion-mesh 1";
  document["note"] =
      "Post-process lens (docs/exports.md, \"distortion-mesh\"): render the pinhole camera into "
      "render_target (its image_size, projection and view; glViewport(0, 0, width, height)), then "
      "draw these triangles into the camera's image with position = distorted_uv * 2 - 1 (NDC) "
      "and texture coordinate undistorted_uv, sampling the render target bilinearly. The grid "
      "covers the render target, so distorted_uv reaches outside [0, 1] (GL clips that). UVs are "
      "window coordinates / size: (0, 0) = bottom-left corner, y up (GL texture coordinates of a "
      "texture whose row 0 is the bottom, as glReadPixels returns it; Nuke's STMap convention).";
  document["image_size"] = {w, h};
  document["step_px"] = step_px;
  document["max_interpolation_error_px"] = worst;
  ordered_json render_target;
  render_target["image_size"] = {target.size.width, target.size.height};
  render_target["offset_px"] = {target.offset_x, target.offset_y};
  render_target["fx"] = target.intrinsics.fx;
  render_target["fy"] = target.intrinsics.fy;
  render_target["cx"] = target.intrinsics.cx;
  render_target["cy"] = target.intrinsics.cy;
  render_target["skew"] = target.intrinsics.skew;
  render_target["near"] = camera.z_near;
  if (std::isfinite(camera.z_far)) {
    render_target["far"] = camera.z_far;
  } else {
    render_target["far"] = "inf";
  }
  render_target["depth"] = ToString(depth.clip_depth);
  render_target["reversed_z"] = depth.reversed_z;
  render_target["projection"] = Matrix4Json(projection);
  render_target["view"] = Matrix4Json(GlEyeFromWorld(camera.cam_from_world));
  document["render_target"] = render_target;
  document["vertex_count"] = window.size();
  document["distorted_uv"] = distorted_uv;
  document["undistorted_uv"] = undistorted_uv;
  document["triangles"] = triangles;
  return document.dump() + "\n";
}

std::string LensDistortionMeshObj(const Camera& camera, int step_px, const GlDepth& depth) {
  const LensRenderTarget target = LensRenderTargetOf(camera);
  if (step_px == 0) step_px = LensMeshStepPx(camera, kLensMeshErrorPx);
  const LensMesh mesh = BuildLensMesh(camera, target, step_px);
  const double worst = LensMeshErrorPx(camera, target, mesh);
  const double w = camera.image_size.width;
  const double h = camera.image_size.height;
  const Eigen::Matrix4d projection =
      ClipFromGlEye(target.intrinsics, target.size, camera.z_near, camera.z_far, depth);
  const Eigen::Matrix4d view = GlEyeFromWorld(camera.cam_from_world);
  auto out = ExactStream();
  out << "# camproj distortion mesh, OBJ form (docs/exports.md, distortion-mesh): k1 = "
      << camera.intrinsics.k1 << ", k2 = " << camera.intrinsics.k2 << "\n"
      << "# v x y 0: where the lens images the vertex on the camera's " << camera.image_size.width
      << " x " << camera.image_size.height << " image, in NDC (distorted_uv * 2 - 1)\n"
      << "# vt u v: the vertex on the render target (undistorted_uv = window / size, y up)\n"
      << "# render target: " << target.size.width << " x " << target.size.height
      << " px, pixel = the camera's pinhole pixel + (" << target.offset_x << ", " << target.offset_y
      << "); fx " << target.intrinsics.fx << ", fy " << target.intrinsics.fy << ", cx "
      << target.intrinsics.cx << ", cy " << target.intrinsics.cy << ", skew "
      << target.intrinsics.skew << " (kCenter); depth " << ToString(depth.clip_depth)
      << (depth.reversed_z ? ", reversed-Z" : "") << "; near " << camera.z_near << ", far "
      << camera.z_far << "\n"
      << "# step " << step_px << " px; max interpolation error " << worst << " px\n"
      << "# projection";
  for (int i = 0; i < 16; ++i) out << ' ' << projection.data()[i];
  out << "\n# view";
  for (int i = 0; i < 16; ++i) out << ' ' << view.data()[i];
  out << '\n';
  for (const Eigen::Vector2d& window : mesh.window) {
    out << "v " << 2.0 * window.x() / w - 1.0 << ' ' << 2.0 * window.y() / h - 1.0 << " 0\n";
  }
  for (const Eigen::Vector2d& source : mesh.source) {
    const Eigen::Vector2d uv = UvOfPixel(source, target.size);
    out << "vt " << uv.x() << ' ' << uv.y() << '\n';
  }
  for (size_t t = 0; t < mesh.triangles.size(); t += 3) {
    out << 'f';
    for (int i = 0; i < 3; ++i) {
      const int index = mesh.triangles[t + i] + 1;  // OBJ counts from 1
      out << ' ' << index << '/' << index;
    }
    out << '\n';
  }
  return out.str();
}

std::string LensRenderTargetText(const Camera& camera, LensMapDirection direction,
                                 const GlDepth& depth) {
  const LensRenderTarget target = LensRenderTargetOf(camera);
  const Eigen::Matrix4d projection =
      ClipFromGlEye(target.intrinsics, target.size, camera.z_near, camera.z_far, depth);
  const int w = camera.image_size.width;
  const int h = camera.image_size.height;
  auto out = ExactStream();
  out << "# camproj "
      << (direction == LensMapDirection::kDistort ? "STMap (distort)" : "STMap (undistort)")
      << ": k1 = " << camera.intrinsics.k1 << ", k2 = " << camera.intrinsics.k2
      << "; 32-bit float RGBA, Nuke's STMap convention (docs/exports.md, \"stmap\"):\n"
      << "# red = x / source width, green = y / source height, x, y the source's window "
         "coordinates (origin at its bottom-left corner, y up)\n";
  if (direction == LensMapDirection::kDistort) {
    out << "# the map is the camera's image, " << w << " x " << h
        << " px; the source is the render target below, " << target.size.width << " x "
        << target.size.height << " px:\n"
        << "# render the pinhole camera there with `projection` and `view` (glViewport(0, 0, "
        << target.size.width << ", " << target.size.height << ")), then warp it with the map\n";
  } else {
    out << "# the map is the render target below, " << target.size.width << " x "
        << target.size.height << " px (the undistorted plate); the source is the camera's image "
        << "(the plate), " << w << " x " << h << " px;\n"
        << "# alpha 0 where the source is off the plate (red = green = -1 beyond the lens's "
           "fold); render CG with `projection` and `view` at "
        << target.size.width << " x " << target.size.height << " to overlay it\n";
  }
  out << "# render target: " << target.size.width << " x " << target.size.height
      << " px, pixel = the camera's pinhole pixel + (" << target.offset_x << ", " << target.offset_y
      << "); fx " << target.intrinsics.fx << ", fy " << target.intrinsics.fy << ", cx "
      << target.intrinsics.cx << ", cy " << target.intrinsics.cy << ", skew "
      << target.intrinsics.skew << " (kCenter)\n"
      << "# projection = clip_from_gl_eye, view = gl_eye_from_world, column-major (GL_FALSE); "
         "depth "
      << ToString(depth.clip_depth) << (depth.reversed_z ? ", reversed-Z" : "") << "; near "
      << camera.z_near << ", far " << camera.z_far << "\n";
  out << "projection";
  for (int i = 0; i < 16; ++i) out << ' ' << projection.data()[i];
  out << "\nview";
  const Eigen::Matrix4d view = GlEyeFromWorld(camera.cam_from_world);
  for (int i = 0; i < 16; ++i) out << ' ' << view.data()[i];
  out << '\n';
  return out.str();
}

}  // namespace camproj

#include "camproj/overlay.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <sstream>

#include <opencv2/imgcodecs.hpp>  // cv::IMREAD_COLOR; the codecs: image_codecs.h
#include <opencv2/imgproc.hpp>

#include "camproj/errors.h"
#include "camproj/file_io.h"
#include "camproj/image_header.h"
#include "camproj/points_file.h"
#include "check.h"
#include "drawing.h"
#include "image_codecs.h"
#include "photo.h"

namespace camproj {

namespace {

// OpenCV draws with integer coordinates in 1/16 px (shift = 4); its pixel centres are at integers,
// as in kCenter.
constexpr int kShift = 4;
cv::Point Fixed(const Eigen::Vector2d& p) {
  return {static_cast<int>(std::lround(p.x() * 16.0)), static_cast<int>(std::lround(p.y() * 16.0))};
}

}  // namespace

void OverlayOptions::Check() const {
  internal::Require(std::isfinite(magnify) && magnify >= 0.0,
                    "magnify must be positive (or 0: automatic), got ", magnify);
  internal::Require(residual_fraction > 0.0 && residual_fraction <= 1.0,
                    "residual_fraction must be in (0, 1], got ", residual_fraction);
}

namespace {

// Viridis (matplotlib's colour-blind-safe, perceptually uniform scale) from OpenCV, as BGR.
cv::Scalar Viridis(double t) {
  static const cv::Mat lut = [] {
    cv::Mat ramp(1, 256, CV_8UC1);
    for (int i = 0; i < 256; ++i) ramp.at<uchar>(0, i) = static_cast<uchar>(i);
    cv::Mat coloured;
    cv::applyColorMap(ramp, coloured, cv::COLORMAP_VIRIDIS);
    return coloured;
  }();
  // NaN (a residual that overflowed, inf / inf) is off the scale at its top, as inf is.
  const double on_scale = std::isnan(t) ? 1.0 : std::clamp(t, 0.0, 1.0);
  const int i = static_cast<int>(std::lround(on_scale * 255.0));
  const cv::Vec3b c = lut.at<cv::Vec3b>(0, i);
  return cv::Scalar(c[0], c[1], c[2]);
}
const cv::Scalar kOutlierColour(31, 90, 255);  // vermillion (BGR), away from viridis's hues
const cv::Scalar kBehindColour(170, 170, 170);
const cv::Scalar kInk(0, 0, 0);
const cv::Scalar kWhite(255, 255, 255);

std::string FormatPx(double px) {
  char text[32];
  std::snprintf(text, sizeof text, px < 10 ? "%.2f" : px < 100 ? "%.1f" : "%.0f", px);
  return text;
}

struct Style {
  double unit;  // px per "design pixel": 1 at 480 px and below, 2 at 1080, 4 at 2160 (4K)
  int line;
  int text_thickness;
  double font_scale;
  double ring;  // radius
};

Style StyleFor(int w, int h) {
  Style s;
  s.unit = std::max(1.0, std::min(w, h) / 540.0);
  s.line = std::max(1, static_cast<int>(std::lround(s.unit)));
  s.text_thickness = std::max(1, static_cast<int>(std::lround(0.8 * s.unit)));
  s.font_scale = 0.45 * s.unit;  // Hershey simplex: digits ~10 px high at 480p, ~20 at 1080p
  s.ring = 6.0 * s.unit;
  return s;
}

// Text with a dark halo, legible on any photo.
void HaloText(cv::Mat& image, const std::string& text, cv::Point origin, const Style& s,
              const cv::Scalar& colour) {
  cv::putText(image, text, origin, cv::FONT_HERSHEY_SIMPLEX, s.font_scale, kInk,
              s.text_thickness + 2 * s.line, cv::LINE_AA);
  cv::putText(image, text, origin, cv::FONT_HERSHEY_SIMPLEX, s.font_scale, colour,
              s.text_thickness, cv::LINE_AA);
}

// Drawing stays within the image widened by this margin (px): wider than any marker, and small
// enough that Fixed's 1/16 px coordinates fit an int (a point 2^27 px away wrapped around into
// the image before session 37).
constexpr double kCanvasMarginPx = 4096.0;

// Whether `p` is within the canvas: the image widened by kCanvasMarginPx.
bool OnCanvas(const cv::Mat& image, const Eigen::Vector2d& p) {
  return p.x() >= -kCanvasMarginPx && p.x() <= image.cols + kCanvasMarginPx &&
         p.y() >= -kCanvasMarginPx && p.y() <= image.rows + kCanvasMarginPx;
}

// The part of segment [a, b] on the canvas (Liang-Barsky); false where none is.
bool ClipToCanvas(const cv::Mat& image, Eigen::Vector2d* a, Eigen::Vector2d* b) {
  const Eigen::Vector2d d = *b - *a;
  const double lo[2] = {-kCanvasMarginPx, -kCanvasMarginPx};
  const double hi[2] = {image.cols + kCanvasMarginPx, image.rows + kCanvasMarginPx};
  double t0 = 0.0;
  double t1 = 1.0;
  for (int axis = 0; axis < 2; ++axis) {
    const double start = (*a)(axis);
    if (d(axis) == 0.0) {
      if (start < lo[axis] || start > hi[axis]) return false;
      continue;
    }
    double enter = (lo[axis] - start) / d(axis);
    double leave = (hi[axis] - start) / d(axis);
    if (enter > leave) std::swap(enter, leave);
    t0 = std::max(t0, enter);
    t1 = std::min(t1, leave);
    if (!(t0 <= t1)) return false;
  }
  // An end on the canvas stays as it is (bit for bit: most segments are not clipped).
  const Eigen::Vector2d start = *a;
  if (t0 > 0.0) *a = start + t0 * d;
  if (t1 < 1.0) *b = start + t1 * d;
  return true;
}

void HaloLine(cv::Mat& image, Eigen::Vector2d a, Eigen::Vector2d b, const Style& s,
              const cv::Scalar& colour) {
  if (!ClipToCanvas(image, &a, &b)) return;
  cv::line(image, Fixed(a), Fixed(b), kInk, s.line + 2, cv::LINE_AA, kShift);
  cv::line(image, Fixed(a), Fixed(b), colour, s.line, cv::LINE_AA, kShift);
}

void Ring(cv::Mat& image, const Eigen::Vector2d& c, const Style& s, const cv::Scalar& colour) {
  if (!OnCanvas(image, c)) return;  // beyond the margin it would not show
  const int r = static_cast<int>(std::lround(s.ring * 16));
  cv::circle(image, Fixed(c), r, kInk, s.line + 2, cv::LINE_AA, kShift);
  cv::circle(image, Fixed(c), r, colour, s.line, cv::LINE_AA, kShift);
}

void Cross(cv::Mat& image, const Eigen::Vector2d& c, double half, const Style& s,
           const cv::Scalar& colour, bool diagonal) {
  const Eigen::Vector2d a = diagonal ? Eigen::Vector2d(half, half) : Eigen::Vector2d(half, 0);
  const Eigen::Vector2d b = diagonal ? Eigen::Vector2d(half, -half) : Eigen::Vector2d(0, half);
  HaloLine(image, c - a, c + a, s, colour);
  HaloLine(image, c - b, c + b, s, colour);
}

void DrawArrow(cv::Mat& image, const std::pair<Eigen::Vector2d, Eigen::Vector2d>& arrow,
               const Style& s, const cv::Scalar& colour) {
  const auto& [tail, tip] = arrow;
  cv::arrowedLine(image, Fixed(tail), Fixed(tip), kInk, 2 * s.line + 3, cv::LINE_AA, kShift, 0.35);
  cv::arrowedLine(image, Fixed(tail), Fixed(tip), colour, 2 * s.line, cv::LINE_AA, kShift, 0.35);
}

struct Box {
  double x0, y0, x1, y1;
  double Overlap(const Box& o) const {
    const double w = std::min(x1, o.x1) - std::max(x0, o.x0);
    const double h = std::min(y1, o.y1) - std::max(y0, o.y0);
    return w > 0 && h > 0 ? w * h : 0.0;
  }
};

// Puts each label at the first of eight places around its marker that covers no marker and no
// label placed before it and stays inside the image; where none does, at the place that covers
// least. Labels are placed in `order` (the largest residuals first: their ids matter most).
std::vector<Box> PlaceLabels(const std::vector<Eigen::Vector2d>& anchors,
                             const std::vector<cv::Size>& sizes, const std::vector<size_t>& order,
                             int w, int h, const Style& s, std::vector<Box> obstacles) {
  for (const Eigen::Vector2d& a : anchors) {
    obstacles.push_back({a.x() - s.ring, a.y() - s.ring, a.x() + s.ring, a.y() + s.ring});
  }
  std::vector<Box> placed(anchors.size());
  const double gap = s.ring + 2.0 * s.unit;
  for (size_t i : order) {
    const double tw = sizes[i].width, th = sizes[i].height;
    const Eigen::Vector2d a = anchors[i];
    const Box candidates[8] = {
        {a.x() + gap, a.y() - gap - th, a.x() + gap + tw, a.y() - gap},          // upper right
        {a.x() + gap, a.y() - th / 2, a.x() + gap + tw, a.y() + th / 2},         // right
        {a.x() + gap, a.y() + gap, a.x() + gap + tw, a.y() + gap + th},          // lower right
        {a.x() - gap - tw, a.y() - gap - th, a.x() - gap, a.y() - gap},          // upper left
        {a.x() - gap - tw, a.y() - th / 2, a.x() - gap, a.y() + th / 2},         // left
        {a.x() - gap - tw, a.y() + gap, a.x() - gap, a.y() + gap + th},          // lower left
        {a.x() - tw / 2, a.y() - gap - th, a.x() + tw / 2, a.y() - gap},         // above
        {a.x() - tw / 2, a.y() + gap, a.x() + tw / 2, a.y() + gap + th}};        // below
    double best_cost = std::numeric_limits<double>::infinity();
    for (const Box& c : candidates) {
      double cost = 0.0;
      // Outside the image costs as much as covering a label of its size.
      const Box inside{std::max(c.x0, 0.0), std::max(c.y0, 0.0), std::min(c.x1, w - 1.0),
                       std::min(c.y1, h - 1.0)};
      cost += tw * th - std::max(0.0, inside.x1 - inside.x0) * std::max(0.0, inside.y1 - inside.y0);
      for (const Box& o : obstacles) cost += c.Overlap(o);
      if (cost < best_cost) {
        best_cost = cost;
        placed[i] = c;
        if (cost == 0.0) break;
      }
    }
    obstacles.push_back(placed[i]);
  }
  return placed;
}

// The legend: symbols, the magnification and what it makes of the largest residual, the colour
// scale, the counts of outliers, points outside the image and behind the camera. Returns its box.
Box DrawLegend(cv::Mat& image, const OverlayStats& stats, const std::vector<Eigen::Vector2d>& anchors,
               const Style& s) {
  std::vector<std::string> lines;
  char magnify_text[32];
  std::snprintf(magnify_text, sizeof magnify_text, "%g", stats.magnify);
  lines.push_back(std::string("o observed    + reprojected    line: residual x ") + magnify_text);
  // Drawn longer than the image's diagonal, its length is clipped (or, beyond a double, inf).
  const double drawn_px = stats.largest_residual_px * stats.magnify;
  const double diagonal_px = std::hypot(image.cols, image.rows);
  lines.push_back("(the largest, " + FormatPx(stats.largest_residual_px) + " px, drawn " +
                  (drawn_px <= diagonal_px ? FormatPx(drawn_px) + " px long)"
                                           : std::string("past the image's edge)")));
  lines.push_back("colour: residual 0 px                    " + FormatPx(stats.largest_residual_px) +
                  " px");
  if (stats.outliers > 0) {
    lines.push_back("x " + std::to_string(stats.outliers) + " left out by the fit (outliers)");
  }
  if (stats.outside > 0) {
    lines.push_back("-> " + std::to_string(stats.outside) + " observed outside the image");
  }
  if (stats.behind > 0) {
    lines.push_back(std::to_string(stats.behind) + " behind the camera (no reprojection)");
  }
  if (stats.no_pixel > 0) {
    lines.push_back(std::to_string(stats.no_pixel) +
                    " in front, pixel beyond a double (no reprojection)");
  }
  int baseline = 0;
  const int line_height =
      cv::getTextSize("Ag", cv::FONT_HERSHEY_SIMPLEX, s.font_scale, s.text_thickness, &baseline)
          .height + baseline + static_cast<int>(4 * s.unit);
  const int pad = static_cast<int>(6 * s.unit);
  int legend_w = 0;
  for (const std::string& line : lines) {
    legend_w = std::max(legend_w, cv::getTextSize(line, cv::FONT_HERSHEY_SIMPLEX, s.font_scale,
                                                  s.text_thickness, &baseline).width);
  }
  legend_w += 2 * pad;
  const int legend_h = static_cast<int>(lines.size()) * line_height + 2 * pad;
  const int w = image.cols, h = image.rows;
  // In the corner that holds the fewest points; darkened, not opaque.
  cv::Point corner(0, 0);
  int fewest = std::numeric_limits<int>::max();
  for (const cv::Point c : {cv::Point(0, 0), cv::Point(w - legend_w, 0), cv::Point(0, h - legend_h),
                            cv::Point(w - legend_w, h - legend_h)}) {
    int covered = 0;
    for (const Eigen::Vector2d& a : anchors) {
      if (a.x() >= c.x - s.ring && a.x() <= c.x + legend_w + s.ring && a.y() >= c.y - s.ring &&
          a.y() <= c.y + legend_h + s.ring) {
        ++covered;
      }
    }
    if (covered < fewest) {
      fewest = covered;
      corner = c;
    }
  }
  {
    cv::Mat region = image(cv::Rect(corner, cv::Size(legend_w, legend_h)) & cv::Rect(0, 0, w, h));
    cv::Mat dark(region.size(), region.type(), cv::Scalar(20, 20, 20));
    cv::addWeighted(region, 0.3, dark, 0.7, 0.0, region);
  }
  for (size_t k = 0; k < lines.size(); ++k) {
    const cv::Point origin(corner.x + pad,
                           corner.y + pad + static_cast<int>(k + 1) * line_height - baseline -
                               static_cast<int>(2 * s.unit));
    HaloText(image, lines[k], origin, s, lines[k][0] == 'x' ? kOutlierColour : kWhite);
    if (lines[k].rfind("colour:", 0) == 0) {
      // The scale between "0 px" and the top value.
      const int x0 = origin.x + cv::getTextSize("colour: residual 0 px ", cv::FONT_HERSHEY_SIMPLEX,
                                                s.font_scale, s.text_thickness, &baseline).width;
      const int x1 = origin.x + cv::getTextSize("colour: residual 0 px                   ",
                                                cv::FONT_HERSHEY_SIMPLEX, s.font_scale,
                                                s.text_thickness, &baseline).width;
      const int y1 = origin.y, y0 = origin.y - line_height + static_cast<int>(6 * s.unit);
      for (int x = x0; x < x1; ++x) {
        cv::line(image, cv::Point(x, y0), cv::Point(x, y1),
                 Viridis(static_cast<double>(x - x0) / std::max(1, x1 - x0 - 1)), 1);
      }
    }
  }

  return Box{static_cast<double>(corner.x), static_cast<double>(corner.y),
             static_cast<double>(corner.x + legend_w), static_cast<double>(corner.y + legend_h)};
}

// What the overlay draws for one point.
struct OverlayPoint {
  std::optional<Eigen::Vector2d> predicted;  // its reprojection (kCenter); none behind the camera
  double residual_px = -1.0;                 // |predicted - observed|; -1 without a reprojection
  std::string kind;                          // as OverlayLabel::kind
  std::string kind_if_inside;                // what "outside" overrides: "point", "outlier", ...
  cv::Scalar colour;
  Eigen::Vector2d anchor;  // where its label goes: the observed pixel, or its border arrow's tip
  std::pair<Eigen::Vector2d, Eigen::Vector2d> arrow;  // kind "outside" only
};

// Each point's reprojection, residual, kind and colour, and the counts and magnification of
// `stats` (the largest residual: over the kept points observed inside the image).
std::vector<OverlayPoint> MeasurePoints(const Camera& camera, const Correspondences& correspondences,
                                        const std::vector<bool>& outlier,
                                        const OverlayOptions& options, const Style& s,
                                        OverlayStats* stats_out) {
  OverlayStats& stats = *stats_out;
  const int w = camera.image_size.width;
  const int h = camera.image_size.height;
  const size_t n = correspondences.pixels.size();
  const auto inside = [&](const Eigen::Vector2d& p) { return PixelInImage(p, camera.image_size); };
  std::vector<OverlayPoint> points(n);
  for (size_t i = 0; i < n; ++i) {
    OverlayPoint& point = points[i];
    const Eigen::Vector2d& observed = correspondences.pixels[i];
    point.predicted = PixelFromWorld(camera, correspondences.points_in_world[i]);
    if (point.predicted) point.residual_px = (*point.predicted - observed).norm();
    if (point.predicted && !outlier[i] && inside(observed)) {
      stats.largest_residual_px = std::max(stats.largest_residual_px, point.residual_px);
    }
  }
  stats.magnify = options.magnify > 0.0
                      ? options.magnify
                      : internal::NiceFloor(stats.largest_residual_px > 0.0
                                      ? options.residual_fraction * std::min(w, h) /
                                            stats.largest_residual_px
                                      : 1.0);
  const double colour_top = std::max(stats.largest_residual_px, 1e-12);
  for (size_t i = 0; i < n; ++i) {
    OverlayPoint& point = points[i];
    const Eigen::Vector2d& observed = correspondences.pixels[i];
    point.anchor = observed;
    if (!point.predicted) {
      // PixelFromWorld has no pixel behind the camera, nor for a point in front whose pixel
      // would be beyond a double: told apart by the depth.
      const bool in_front = (camera.cam_from_world * correspondences.points_in_world[i]).z() > 0.0;
      point.kind = in_front ? "no-pixel" : "behind";
      point.colour = kBehindColour;
      ++(in_front ? stats.no_pixel : stats.behind);
    } else if (outlier[i]) {
      point.kind = "outlier";
      point.colour = kOutlierColour;
      ++stats.outliers;
    } else {
      point.kind = "point";
      point.colour = Viridis(point.residual_px / colour_top);
      ++stats.drawn;
    }
    point.kind_if_inside = point.kind;
    if (!inside(observed)) {
      point.kind = "outside";
      ++stats.outside;
      point.arrow = internal::BorderArrow(observed, w, h, 4.0 * s.ring);
      point.anchor = point.arrow.first;
    }
  }
  return points;
}

// The markers: a ring at each observed pixel, with the magnified residual and a cross at the
// reprojection for a kept point, a cross inside the ring for an outlier, an arrow at the border
// for a point outside the image.
void DrawMarkers(cv::Mat& image, const std::vector<OverlayPoint>& points,
                 const Correspondences& correspondences, double magnify, const Style& s) {
  for (size_t i = 0; i < points.size(); ++i) {
    const OverlayPoint& point = points[i];
    const Eigen::Vector2d& observed = correspondences.pixels[i];
    if (point.kind == "outside") {
      DrawArrow(image, point.arrow, s, point.colour);
    } else if (point.kind == "point") {
      HaloLine(image, observed, observed + magnify * (*point.predicted - observed), s,
               point.colour);
      Cross(image, *point.predicted, 0.8 * s.ring, s, kWhite, false);
      Ring(image, observed, s, point.colour);
    } else if (point.kind == "outlier") {
      Ring(image, observed, s, point.colour);
      Cross(image, observed, 0.7 * s.ring, s, point.colour, true);
    } else {
      Ring(image, observed, s, point.colour);
    }
  }
}

// A point's label: its id (printable, cut to 24 characters), and for an outlier how far off it
// is, for a point outside the image where it is (in `origin`'s convention) and whether it is an
// outlier or behind the camera.
std::string LabelText(const OverlayPoint& point, const std::string& id,
                      const Eigen::Vector2d& observed, PixelOrigin origin) {
  std::string text = id;
  if (text.size() > 24) text = text.substr(0, 23) + "~";
  for (char& c : text) {
    if (static_cast<unsigned char>(c) < 32 || static_cast<unsigned char>(c) > 126) c = '?';
  }
  const std::string& kind = point.kind_if_inside;
  std::string state;
  if (kind == "outlier") state = FormatPx(point.residual_px) + " px off";
  if (kind == "behind") state = "behind";
  if (kind == "no-pixel") state = "no pixel";
  if (point.kind == "outside") {
    const Eigen::Vector2d at = ConvertPixelOrigin(observed, PixelOrigin::kCenter, origin);
    char where[64];
    std::snprintf(where, sizeof where, "at %.0f, %.0f", at.x(), at.y());
    state = state.empty() ? std::string(where) : std::string(where) + "; " + state;
  }
  return state.empty() ? text : text + " (" + state + ")";
}

// The labels, placed around `anchors` (the points' OverlayPoint::anchor) clear of each other
// and of the legend (the outliers first, then the points outside, then by residual), drawn, and
// listed in stats.labels.
void DrawLabels(cv::Mat& image, const std::vector<OverlayPoint>& points,
                const std::vector<Eigen::Vector2d>& anchors,
                const Correspondences& correspondences, const Box& legend_box, const Style& s,
                PixelOrigin origin, OverlayStats* stats) {
  const int w = image.cols;
  const int h = image.rows;
  const size_t n = points.size();
  std::vector<std::string> texts(n);
  std::vector<cv::Size> sizes(n);
  for (size_t i = 0; i < n; ++i) {
    texts[i] = LabelText(points[i], correspondences.ids[i], correspondences.pixels[i], origin);
    int baseline = 0;
    const cv::Size size =
        cv::getTextSize(texts[i], cv::FONT_HERSHEY_SIMPLEX, s.font_scale, s.text_thickness, &baseline);
    sizes[i] = cv::Size(size.width + 2 * s.line, size.height + baseline + 2 * s.line);
  }
  std::vector<size_t> order(n);
  for (size_t i = 0; i < n; ++i) order[i] = i;
  const auto rank = [&](size_t i) {
    const std::string& kind = points[i].kind;
    return kind == "outlier" ? 2e300 : kind == "outside" ? 1e300 : points[i].residual_px;
  };
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return rank(a) > rank(b); });
  const std::vector<Box> boxes = PlaceLabels(anchors, sizes, order, w, h, s, {legend_box});
  for (size_t i = 0; i < n; ++i) {
    const OverlayPoint& point = points[i];
    const Box& b = boxes[i];
    int baseline = 0;
    cv::getTextSize(texts[i], cv::FONT_HERSHEY_SIMPLEX, s.font_scale, s.text_thickness, &baseline);
    HaloText(image, texts[i],
             cv::Point(static_cast<int>(std::lround(b.x0 + s.line)),
                       static_cast<int>(std::lround(b.y1 - baseline - s.line))),
             s, point.kind == "point" ? kWhite : point.colour);
    OverlayLabel label;
    label.id = correspondences.ids[i];
    label.kind = point.kind;
    label.anchor = point.kind == "outside" ? correspondences.pixels[i] : point.anchor;
    label.box = Eigen::Vector4d(b.x0, b.y0, b.x1 - b.x0, b.y1 - b.y0);
    label.residual_px = point.residual_px;
    label.text = texts[i];
    stats->labels.push_back(label);
  }
}

}  // namespace

OverlayPicture DrawOverlayImage(const Camera& camera, const Correspondences& correspondences,
                                const OverlayOptions& options, ImageFormat format) {
  options.Check();
  camera.Check();
  const int w = camera.image_size.width;
  const int h = camera.image_size.height;
  if (int64_t{w} * h > kMaxImagePixels) {
    throw std::invalid_argument(internal::Concat(
        "the camera's image size ", w, "x", h, " is beyond the ", kMaxImagePixels,
        " pixels an overlay may have (8192 x 8192)"));
  }
  const size_t n = correspondences.pixels.size();
  std::vector<bool> outlier(n, false);
  for (int i : options.outliers) {
    internal::Require(i >= 0 && static_cast<size_t>(i) < n, "outlier index ", i,
                      " is beyond the ", n, " points (are they the points the camera was fitted to?)");
    outlier[i] = true;
  }
  cv::Mat image;
  if (options.background_path.empty()) {
    image = cv::Mat(h, w, CV_8UC3, cv::Scalar(40, 40, 40));
  } else {
    image = internal::DecodePhoto(internal::ReadPhoto(options.background_path, w, h));
  }
  const Style s = StyleFor(w, h);
  OverlayStats stats;
  const std::vector<OverlayPoint> points =
      MeasurePoints(camera, correspondences, outlier, options, s, &stats);
  // The legend first, so that markers and ids stay on top of it; then the markers, and the ids
  // placed around them.
  std::vector<Eigen::Vector2d> anchors(n);
  for (size_t i = 0; i < n; ++i) anchors[i] = points[i].anchor;
  const Box legend_box = DrawLegend(image, stats, anchors, s);
  DrawMarkers(image, points, correspondences, stats.magnify, s);
  DrawLabels(image, points, anchors, correspondences, legend_box, s, options.pixel_origin, &stats);

  std::vector<uchar> encoded;
  const char* extension = format == ImageFormat::kPng ? ".png" : ".jpg";
  if (!internal::EncodeImage(extension, image, &encoded)) {
    throw InputError(internal::Concat("cannot encode the image as ", extension));
  }
  return {std::string(encoded.begin(), encoded.end()), std::move(stats)};
}

OverlayStats WriteOverlayImage(const Camera& camera, const Correspondences& correspondences,
                               const OverlayOptions& options, const std::string& output_path) {
  OverlayPicture picture =
      DrawOverlayImage(camera, correspondences, options, ImageFormatOfPath(output_path));
  WriteFileAtomically(output_path, picture.encoded);
  return std::move(picture.stats);
}

std::string OverlayLabelsCsv(const OverlayStats& stats, PixelOrigin pixel_origin) {
  std::ostringstream out;
  out.precision(10);
  out << "id,kind,u,v,left,top,width,height,residual_px\n";
  for (const OverlayLabel& l : stats.labels) {
    const Eigen::Vector2d anchor = ConvertPixelOrigin(l.anchor, PixelOrigin::kCenter, pixel_origin);
    const Eigen::Vector2d top_left = ConvertPixelOrigin(Eigen::Vector2d(l.box[0], l.box[1]),
                                                        PixelOrigin::kCenter, pixel_origin);
    out << CsvField(l.id) << ',' << l.kind << ',' << anchor.x() << ',' << anchor.y() << ','
        << top_left.x() << ',' << top_left.y() << ',' << l.box[2] << ',' << l.box[3] << ','
        << l.residual_px << '\n';
  }
  return out.str();
}

}  // namespace camproj

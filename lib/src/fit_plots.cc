#include "camproj/fit_plots.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <sstream>

#include "check.h"
#include "drawing.h"

namespace camproj {

using internal::MarkupEscape;
using internal::NiceFloor;
using internal::Utf8Prefix;

namespace {

// Viridis, a few stops (matplotlib's colour-blind-safe scale), as in the overlay and the view.
const int kViridis[][3] = {{68, 1, 84},    {72, 40, 120},  {62, 74, 137},  {49, 104, 142},
                           {38, 130, 142}, {31, 158, 137}, {53, 183, 121}, {110, 206, 88},
                           {181, 222, 43}, {253, 231, 37}};
constexpr const char* kOutlier = "#ff5a1f";

std::string Viridis(double t) {
  t = std::clamp(t, 0.0, 1.0) * 9.0;
  const int i = std::min(8, static_cast<int>(t));
  const double f = t - i;
  char text[16];
  int c[3];
  for (int k = 0; k < 3; ++k) {
    c[k] = static_cast<int>(std::lround(kViridis[i][k] + f * (kViridis[i + 1][k] - kViridis[i][k])));
  }
  std::snprintf(text, sizeof text, "#%02x%02x%02x", c[0], c[1], c[2]);
  return text;
}

// x in 7 significant digits: a coordinate of any size (Num's %f of 1e300 is 300 digits).
std::string Short(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.7g", x);
  return text;
}

std::string Num(double x, int digits = 2) {
  char text[32];
  std::snprintf(text, sizeof text, "%.*f", digits, x);
  return text;
}

// The decimals that tell ticks `step` apart (NiceStep's steps are 1, 2 or 5 times a power of ten):
// 0.0002 for a step of 2e-4, where a fixed 2 wrote 0.00 at every tick.
int TickDecimals(double step) {
  return std::clamp(static_cast<int>(-std::floor(std::log10(step) + 1e-9)), 0, 12);
}

double NiceStep(double range, int ticks) {
  const double raw = range / std::max(1, ticks);
  const double decade = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0, 10.0}) {
    if (m * decade >= raw) return m * decade;
  }
  return 10.0 * decade;
}

constexpr double kWidth = 960;
constexpr double kMargin = 56;

}  // namespace

std::string FitReportFormatOfPath(const std::string& path) {
  std::string extension = std::filesystem::path(path).extension().string();
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (extension == ".svg") return "svg";
  if (extension == ".html" || extension == ".htm") return "html";
  throw std::invalid_argument("a report is .svg or .html, got \"" + path + "\"");
}

namespace {

// The residuals the report draws: their lengths, which points the fit left out, the largest
// kept one (the colour scale's top).
struct ReportResiduals {
  std::vector<bool> outlier;
  std::vector<double> length;  // px; inf for a point behind the camera
  double largest = 0.0;        // px, over the kept points with a finite residual
  // What the colour scale's top stands for (> 0).
  double ColourTop() const { return std::max(largest, 1e-12); }
};

ReportResiduals ResidualsOf(const FitResult& fit) {
  const size_t n = fit.residuals_px.size();
  ReportResiduals r;
  r.outlier.assign(n, false);
  for (int i : fit.outliers) {
    if (i >= 0 && static_cast<size_t>(i) < n) r.outlier[i] = true;
  }
  r.length.resize(n);
  for (size_t i = 0; i < n; ++i) {
    r.length[i] = fit.residuals_px[i].norm();
    if (!r.outlier[i] && std::isfinite(r.length[i])) r.largest = std::max(r.largest, r.length[i]);
  }
  return r;
}

constexpr double kPlotWidth = kWidth - 2 * kMargin;

// The panels, each drawn into `body` below height `y`; each returns the height below it.

// 1. Residual per point: a bar per point in input order, the RMS as a line.
double DrawResidualBars(const FitResult& fit, const ReportResiduals& residuals,
                        const std::vector<std::string>& ids, std::ostream& body) {
  const size_t n = fit.residuals_px.size();
  const std::vector<bool>& outlier = residuals.outlier;
  const std::vector<double>& length = residuals.length;
  const double largest = residuals.largest, colour_top = residuals.ColourTop();
  const double top = 34, h = 200;
  const double axis_max = std::max(largest * 1.15, 1e-3);
  const double step = NiceStep(axis_max, 5);
  body << "<text x='" << kMargin << "' y='" << top - 12
       << "' class='title'>Residual per point (px), input order; RMS " << Num(fit.rms_px, 3)
       << " px, the fit's outliers in vermillion</text>\n";
  for (double v = 0; v <= axis_max + 1e-12; v += step) {
    const double yy = top + h - v / axis_max * h;
    body << "<line x1='" << kMargin << "' x2='" << kMargin + kPlotWidth << "' y1='" << yy << "' y2='"
         << yy << "' class='grid'/><text x='" << kMargin - 6 << "' y='" << yy + 4
         << "' class='tick' text-anchor='end'>" << Num(v, TickDecimals(step))
         << "</text>\n";
  }
  const double slot = kPlotWidth / std::max<size_t>(n, 1);
  const bool show_ids = slot >= 9;
  for (size_t i = 0; i < n; ++i) {
    const double x = kMargin + i * slot;
    const bool beyond = !std::isfinite(length[i]) || length[i] > axis_max;
    const double v = beyond ? axis_max : length[i];
    const double bar_h = v / axis_max * h;
    const std::string colour = outlier[i] ? kOutlier : Viridis(length[i] / colour_top);
    body << "<rect x='" << x + slot * 0.15 << "' y='" << top + h - bar_h << "' width='"
         << slot * 0.7 << "' height='" << bar_h << "' fill='" << colour << "'><title>"
         << MarkupEscape(ids[i]) << ": " << Num(length[i], 3) << " px" << (outlier[i] ? " (outlier)" : "")
         << "</title></rect>\n";
    if (beyond) {
      body << "<text x='" << x + slot / 2 << "' y='" << top - 2
           << "' class='tick' text-anchor='middle' fill='" << kOutlier << "'>"
           << (std::isfinite(length[i]) ? Num(length[i], 0) : std::string("inf")) << "</text>\n";
    }
    if (show_ids) {
      body << "<text transform='translate(" << x + slot / 2 + 3 << "," << top + h + 8
           << ") rotate(-90)' class='tick' text-anchor='end'>" << MarkupEscape(Utf8Prefix(ids[i], 12))
           << "</text>\n";
    }
  }
  const double rms_y = top + h - std::min(fit.rms_px, axis_max) / axis_max * h;
  body << "<line x1='" << kMargin << "' x2='" << kMargin + kPlotWidth << "' y1='" << rms_y
       << "' y2='" << rms_y << "' class='rms'/><text x='" << kMargin + kPlotWidth << "' y='"
       << rms_y - 4 << "' class='tick' text-anchor='end'>RMS</text>\n";
  return top + h + (show_ids ? 64 : 20);
}

// 2. Residuals over the image: an arrow per kept point (magnified), a cross per left-out one.
double DrawResidualsOverImage(const FitResult& fit, const ReportResiduals& residuals,
                              const std::vector<Eigen::Vector2d>& observed_pixels,
                              const std::vector<std::string>& ids, double y, std::ostream& body) {
  const size_t n = fit.residuals_px.size();
  const std::vector<bool>& outlier = residuals.outlier;
  const std::vector<double>& length = residuals.length;
  const double largest = residuals.largest, colour_top = residuals.ColourTop();
  const double w_img = fit.camera.image_size.width, h_img = fit.camera.image_size.height;
  const double scale = std::min(kPlotWidth / w_img, 420.0 / h_img);
  const double x0 = kMargin, y0 = y + 30;
  // Residuals below kRoundingPx are a double's rounding (exact data: 1e-13 px), not drawn
  // magnified 1e15 times as if they were a pattern.
  constexpr double kRoundingPx = 1e-6;
  const double magnify =
      largest > kRoundingPx ? NiceFloor(0.15 * std::min(w_img, h_img) / largest) : 1.0;
  char title[160];
  if (largest > kRoundingPx) {
    std::snprintf(title, sizeof title,
                  "Residuals over the image (%gx%g px): arrows x %g, the largest (%s px) drawn %s px",
                  w_img, h_img, magnify, Num(largest, 2).c_str(), Num(largest * magnify, 0).c_str());
  } else {
    std::snprintf(title, sizeof title,
                  "Residuals over the image (%gx%g px): all below %g px (rounding), no arrows",
                  w_img, h_img, kRoundingPx);
  }
  body << "<text x='" << kMargin << "' y='" << y0 - 12 << "' class='title'>" << title << "</text>\n";
  body << "<rect x='" << x0 << "' y='" << y0 << "' width='" << w_img * scale << "' height='"
       << h_img * scale << "' class='image'/>\n";
  // kCenter pixel p lies at (p + 0.5) * scale from the image's outer corner.
  const auto sx = [&](double u) { return x0 + (u + 0.5) * scale; };
  const auto sy = [&](double v) { return y0 + (v + 0.5) * scale; };
  // An observed pixel outside the image (kCenter: it spans -0.5 to w - 0.5) is an arrow at the
  // border pointing at it, 24 report px long, with its id and where it is.
  const double border_arrow_px = 24.0 / scale;
  const int w = fit.camera.image_size.width, h = fit.camera.image_size.height;
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d& o = observed_pixels[i];
    const std::string id = MarkupEscape(ids[i]);
    const bool left_out = outlier[i] || !std::isfinite(length[i]);
    if (!PixelInImage(o, fit.camera.image_size)) {
      const auto [tail, tip] = internal::BorderArrow(o, w, h, border_arrow_px);
      const std::string colour = left_out ? kOutlier : Viridis(length[i] / colour_top);
      body << "<line x1='" << sx(tail.x()) << "' y1='" << sy(tail.y()) << "' x2='" << sx(tip.x())
           << "' y2='" << sy(tip.y()) << "' stroke='" << colour
           << "' stroke-width='2' marker-end='url(#head)'><title>" << id << ": observed at ("
           << Short(o.x()) << ", " << Short(o.y()) << "), outside the image; " << Num(length[i], 3)
           << " px" << (left_out ? ", left out" : "") << "</title></line>\n";
      body << "<text x='" << sx(tail.x()) + 5 << "' y='" << sy(tail.y()) + 12 << "' class='id'>"
           << id << " (outside)</text>\n";
      continue;
    }
    if (left_out) {
      const double r = 4;
      body << "<g stroke='" << kOutlier << "' stroke-width='2'><line x1='" << sx(o.x()) - r
           << "' y1='" << sy(o.y()) - r << "' x2='" << sx(o.x()) + r << "' y2='" << sy(o.y()) + r
           << "'/><line x1='" << sx(o.x()) - r << "' y1='" << sy(o.y()) + r << "' x2='"
           << sx(o.x()) + r << "' y2='" << sy(o.y()) - r << "'/><title>" << id << ": "
           << Num(length[i], 1) << " px, left out</title></g>\n";
      body << "<text x='" << sx(o.x()) + 6 << "' y='" << sy(o.y()) - 6 << "' class='tick' fill='"
           << kOutlier << "'>" << id << "</text>\n";
      continue;
    }
    const Eigen::Vector2d tip = o + magnify * fit.residuals_px[i];
    const std::string colour = Viridis(length[i] / colour_top);
    body << "<line x1='" << sx(o.x()) << "' y1='" << sy(o.y()) << "' x2='" << sx(tip.x())
         << "' y2='" << sy(tip.y()) << "' stroke='" << colour
         << "' stroke-width='2' marker-end='url(#head)'><title>" << id << ": "
         << Num(length[i], 3) << " px</title></line>\n";
    body << "<circle cx='" << sx(o.x()) << "' cy='" << sy(o.y()) << "' r='2.2' fill='#222'/>"
         << "<text x='" << sx(o.x()) + 5 << "' y='" << sy(o.y()) + 12 << "' class='id'>" << id
         << "</text>\n";
  }
  return y0 + h_img * scale + 20;
}

// 3. The model-selection ladder: each model tried, its criterion as a bar, or why it was not.
double DrawLadder(const FitResult& fit, double y, std::ostream& body) {
  const double top = y + 30, row = 22;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const ModelCandidate& c : fit.candidates) {
    if (c.fitted && std::isfinite(c.criterion)) {
      lo = std::min(lo, c.criterion);
      hi = std::max(hi, c.criterion);
    }
  }
  if (!(hi > lo)) {
    hi = lo + 1;
    lo -= 1;
  }
  const double label_w = 300, bar_x = kMargin + label_w, bar_w = kPlotWidth - label_w - 150;
  body << "<text x='" << kMargin << "' y='" << top - 12 << "' class='title'>Models tried, in order: "
       << MarkupEscape(fit.criterion) << " (lower is better; chosen: " << MarkupEscape(fit.model)
       << ")</text>\n";
  for (size_t k = 0; k < fit.candidates.size(); ++k) {
    const ModelCandidate& c = fit.candidates[k];
    const double yy = top + k * row;
    const bool chosen = c.name == fit.model;
    body << "<text x='" << kMargin << "' y='" << yy + 14 << "' class='" << (chosen ? "chosen" : "model")
         << "'>" << MarkupEscape(c.name) << "</text>\n";
    if (c.fitted && std::isfinite(c.criterion)) {
      const double x = bar_x + (c.criterion - lo) / (hi - lo) * bar_w;
      body << "<line x1='" << bar_x << "' x2='" << x << "' y1='" << yy + 10 << "' y2='" << yy + 10
           << "' class='ladder'/><circle cx='" << x << "' cy='" << yy + 10 << "' r='5' fill='"
           << (chosen ? "#2f6fb0" : "#888") << "'><title>" << MarkupEscape(c.verdict)
           << "</title></circle><text x='" << x + 9 << "' y='" << yy + 14 << "' class='tick'>"
           << Num(c.criterion, 1) << ", RMS " << Num(c.rms_px, 2) << " px</text>\n";
    } else {
      body << "<text x='" << bar_x << "' y='" << yy + 14 << "' class='refused'>"
           << MarkupEscape(Utf8Prefix(c.verdict, 90)) << "</text>\n";
    }
  }
  return top + fit.candidates.size() * row + 10;
}

}  // namespace

std::string FitReportSvg(const FitResult& fit, const std::vector<Eigen::Vector2d>& observed_pixels,
                         const std::vector<std::string>& ids) {
  const size_t n = fit.residuals_px.size();
  internal::Require(observed_pixels.size() == n && ids.size() == n, "the report needs ", n,
                    " observed pixels and ids (one per residual), got ", observed_pixels.size(),
                    " and ", ids.size());
  const ReportResiduals residuals = ResidualsOf(fit);
  std::ostringstream body;
  double y = DrawResidualBars(fit, residuals, ids, body);
  y = DrawResidualsOverImage(fit, residuals, observed_pixels, ids, y, body);
  if (!fit.candidates.empty()) y = DrawLadder(fit, y, body);

  std::ostringstream svg;
  svg << "<svg xmlns='http://www.w3.org/2000/svg' width='" << kWidth << "' height='" << y + 10
      << "' viewBox='0 0 " << kWidth << " " << y + 10
      << "' font-family='system-ui, sans-serif' font-size='12'>\n"
      << "<style>.title{font-size:13px;font-weight:600;fill:#222}.tick{font-size:11px;fill:#444}"
         ".grid{stroke:#ddd}.id{font-size:10px;fill:#777}.rms{stroke:#2f6fb0;stroke-dasharray:5 3}"
         ".image{fill:#f3f3f3;stroke:#999}.model{fill:#333}.chosen{fill:#2f6fb0;font-weight:700}"
         ".ladder{stroke:#ccc;stroke-width:2}.refused{fill:#999;font-style:italic;font-size:11px}"
         "</style>\n"
      << "<defs><marker id='head' viewBox='0 0 10 10' refX='9' refY='5' markerWidth='4' "
         "markerHeight='4' orient='auto-start-reverse'><path d='M0,0 L10,5 L0,10 z' "
         "fill='context-stroke'/></marker></defs>\n"
      << "<rect width='100%' height='100%' fill='white'/>\n"
      << body.str() << "</svg>\n";
  return svg.str();
}

std::string FitReportHtml(const FitResult& fit, const std::vector<Eigen::Vector2d>& observed_pixels,
                          const std::vector<std::string>& ids, const std::string& summary_text,
                          const std::string& title) {
  std::ostringstream html;
  html << "<!doctype html>\n<html lang='en'><head><meta charset='utf-8'><title>" << MarkupEscape(title)
       << "</title>\n<style>body{font:13px system-ui,sans-serif;margin:16px;color:#222;display:flex;"
          "gap:24px;flex-wrap:wrap}pre{font-size:12px;max-width:720px;white-space:pre-wrap}</style>"
          "</head><body>\n<div>"
       << FitReportSvg(fit, observed_pixels, ids) << "</div>\n<pre>" << MarkupEscape(summary_text)
       << "</pre>\n</body></html>\n";
  return html.str();
}

}  // namespace camproj

#include "camproj/fit_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <sstream>

#include "camproj/conventions.h"

namespace camproj {

namespace {

std::string Format(const char* format, double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, format, value);
  return buffer;
}

// Enough significant digits to show the sigma's second digit.
std::string WithSigma(double value, double sigma) {
  if (!(sigma > 0.0) || !std::isfinite(sigma)) return Format("%.6g", value);
  const int decimals = std::clamp(1 - static_cast<int>(std::floor(std::log10(sigma))), 0, 12);
  char buffer[96];
  std::snprintf(buffer, sizeof buffer, "%.*f +- %.*f", decimals, value, decimals, sigma);
  return buffer;
}

}  // namespace

std::string ParameterSigmaText(const ParameterSigma& parameter) {
  return parameter.name + " = " + WithSigma(parameter.value, parameter.sigma) +
         (parameter.unit.empty() ? "" : " ") +
         (parameter.unit == "world" ? "(world units)" : parameter.unit);
}

FitRecord FitRecordOf(const FitResult& fit) {
  FitRecord record;
  record.rms_px = fit.rms_px;
  record.median_px = fit.median_px;
  record.max_px = fit.max_px;
  record.num_points = static_cast<int>(fit.residuals_px.size() - fit.outliers.size());
  record.start = fit.start_method;
  record.model = fit.model;
  record.criterion = fit.criterion;
  record.selection_sigma_px = fit.selection_sigma_px;
  for (const ModelCandidate& c : fit.candidates) {
    record.candidates.push_back({c.name, c.fitted ? c.num_params : 0, c.rms_px, c.criterion, c.verdict});
  }
  record.free = fit.free_parameters;
  for (const FixedParameter& p : fit.fixed_parameters) {
    record.fixed.emplace_back(p.name, p.value + " (" + p.why + ")");
    if (p.why.rfind("default", 0) == 0 || p.why.rfind("left out", 0) == 0) {
      record.left_out.emplace_back(p.name, p.why);
    }
  }
  for (const ParameterSigma& s : fit.sigmas) record.sigma.emplace_back(s.name, s.sigma);
  record.outliers = fit.outliers;
  record.outlier_method = fit.outlier_method;
  for (const LeftOutPoint& p : fit.left_out) {
    record.outlier_points.push_back({p.index, p.residual_px, p.rms_with_px});
  }
  if (fit.consistency.checked) record.consistency = fit.consistency.summary;
  if (fit.determination.checked) record.determination = fit.determination.summary;
  if (fit.reliability.checked) record.reliability = fit.reliability.summary;
  record.pixel_sigma = fit.pixel_sigma;
  record.pixel_sigma_estimated = fit.pixel_sigma_estimated;
  record.iterations = fit.iterations;
  record.jacobian_condition = fit.jacobian_condition;
  record.linearity = fit.linearity;
  record.time_ms = fit.time_ms;
  return record;
}

std::string LinearityText(const LinearityCheck& check) {
  char numbers[200];
  std::snprintf(numbers, sizeof numbers,
                "an error at the edge of the %g %% region can read up to %.3g times its "
                "chi-square in the covariance (bound %.3g), along ",
                100.0 * check.level, 1.0 + check.worst_deviation, 1.0 + check.bound);
  const std::string measured = numbers + check.worst_direction;
  return check.linear ? "the sigmas hold (" + measured + ")"
                      : "curved within the noise's reach: the sigmas are first-order only (" +
                            measured + "); more points, spread in depth, or fewer free "
                            "intrinsics make them hold";
}

namespace {

// A point's id, or its 1-based row where the file has none.
std::string PointName(const std::vector<std::string>& ids, int i) {
  return i < static_cast<int>(ids.size()) ? ids[i] : std::to_string(i + 1);
}

// The points used (outliers are listed apart), the largest residual first.
std::vector<int> WorstFirst(const FitResult& fit) {
  const int n = static_cast<int>(fit.residuals_px.size());
  std::vector<int> order;
  for (int i = 0; i < n; ++i) {
    if (!std::binary_search(fit.outliers.begin(), fit.outliers.end(), i)) order.push_back(i);
  }
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    return fit.residuals_px[a].norm() > fit.residuals_px[b].norm();
  });
  return order;
}

// The model, the models tried and the fixed intrinsics.
void WriteModel(const FitResult& fit, std::ostream& out) {
  const int n = static_cast<int>(fit.residuals_px.size());
  out << "model: " << fit.model << ", " << fit.free_parameters.size()
      << " free parameters (pose";
  for (const std::string& name : fit.free_parameters) {
    if (name.rfind("rotation", 0) != 0 && name.rfind("eye", 0) != 0) out << ", " << name;
  }
  // The points fitted (those left out are listed below, "left out of the fit").
  const int kept = n - static_cast<int>(fit.outliers.size());
  out << "), " << (kept < n ? std::to_string(kept) + " of " : "") << n << " points"
      << (fit.planar ? " (coplanar)" : "") << ", start " << fit.start_method << "\n";
  if (!fit.candidates.empty()) {
    // One candidate is no choice: the model was forced (--model), or nothing else was open.
    out << "  " << (fit.candidates.size() > 1 ? "chosen automatically by " : "the only model open; ")
        << fit.criterion << " at pixel noise " << Format("%.3g", fit.selection_sigma_px)
        << " px; models tried:\n";
    for (const ModelCandidate& c : fit.candidates) {
      out << "    " << c.name;
      if (c.fitted) {
        out << " (" << c.num_params << " parameters, rms " << Format("%.3f", c.rms_px) << " px, "
            << fit.criterion << " " << Format("%.1f", c.criterion) << ")";
      }
      out << ": " << c.verdict << "\n";
    }
  }
  for (const FixedParameter& p : fit.fixed_parameters) {
    out << "  fixed " << p.name << " = " << p.value << " (" << p.why << ")\n";
  }
}

// The parameters' sigmas and strong correlations.
void WriteUncertainty(const FitResult& fit, std::ostream& out) {
  if (fit.covariance_available) {
    std::string source = fit.pixel_sigma_estimated ? "estimated from the residuals" : "given";
    if (fit.consistency.checked && fit.pixel_sigma_estimated) {
      source = "from the residuals and the " + Format("%.3g", fit.consistency.noise_px) +
               " px prior";
    }
    out << "parameters (+- 1 sigma, pixel noise " << Format("%.3g", fit.pixel_sigma) << " px "
        << source << "):\n";
    const double shift = PixelOriginShift(PixelOrigin::kCenter, fit.pixel_origin);
    for (ParameterSigma s : fit.sigmas) {
      if (s.name.rfind("rotation", 0) == 0) continue;
      if (s.name == "cx" || s.name == "cy") s.value += shift;  // the sigmas' cx, cy are kCenter
      out << "  " << ParameterSigmaText(s) << "\n";
    }
    double rotation_sigma = 0.0;
    for (const ParameterSigma& s : fit.sigmas) {
      if (s.name.rfind("rotation", 0) == 0) rotation_sigma = std::max(rotation_sigma, s.sigma);
    }
    out << "  rotation +- " << Format("%.2g", rotation_sigma) << " deg (largest about a camera axis)\n";
    for (const Correlation& c : fit.strong_correlations) {
      out << "  strongly correlated: " << c.first << ", " << c.second << " ("
          << Format("%+.3f", c.correlation) << ")\n";
    }
  } else if (!fit.no_uncertainty_why.empty()) {
    out << "parameters: no uncertainty (" << fit.no_uncertainty_why << ")\n";
  } else {
    out << "parameters: no uncertainty (as many equations as unknowns and no --sigma given)\n";
  }
}

// The camera: intrinsics, look-at, the GL view (ortho, perspective or frustum), near and far.
void WriteCamera(const FitResult& fit, std::ostream& out) {
  const Intrinsics k =
      ConvertPixelOrigin(fit.camera.intrinsics, PixelOrigin::kCenter, fit.pixel_origin);
  out << "intrinsics: fx " << Format("%.6g", k.fx) << " fy " << Format("%.6g", k.fy) << " cx "
      << Format("%.6g", k.cx) << " cy " << Format("%.6g", k.cy);
  if (k.skew != 0.0) out << " skew " << Format("%.6g", k.skew);
  if (k.HasDistortion()) out << " k1 " << Format("%.6g", k.k1) << " k2 " << Format("%.6g", k.k2);
  if (k.HasBeyondTwoRadial()) {
    out << " p1 " << Format("%.6g", k.p1) << " p2 " << Format("%.6g", k.p2) << " k3 "
        << Format("%.6g", k.k3);
  }
  out << (fit.pixel_origin == PixelOrigin::kCenter ? " (px, pixel centres at integers)\n"
                                                    : " (px, pixel corners at integers)\n");
  const LookAt& look = fit.views.look_at;
  auto vec = [](const Eigen::Vector3d& v) {
    return Format("%.6g", v.x()) + " " + Format("%.6g", v.y()) + " " + Format("%.6g", v.z());
  };
  out << "look-at: eye " << vec(look.eye) << ", target " << vec(look.target) << ", up "
      << vec(look.up) << "\n";
  if (fit.views.ortho) {
    const Ortho& o = *fit.views.ortho;
    out << "ortho (orthographic, world units): left " << Format("%.6g", o.left) << " right "
        << Format("%.6g", o.right) << " bottom " << Format("%.6g", o.bottom) << " top "
        << Format("%.6g", o.top) << "\n";
  } else if (fit.views.perspective) {
    out << "perspective: fovy " << Format("%.6g", fit.views.perspective->fovy_deg) << " deg, aspect "
        << Format("%.6g", fit.views.perspective->aspect) << "\n";
  } else if (fit.views.frustum) {
    const Frustum& f = *fit.views.frustum;
    out << "frustum (off-axis): left " << Format("%.6g", f.left) << " right " << Format("%.6g", f.right)
        << " bottom " << Format("%.6g", f.bottom) << " top " << Format("%.6g", f.top) << "\n";
  }
  out << "near " << Format("%.6g", fit.camera.z_near) << ", far " << Format("%.6g", fit.camera.z_far)
      << " (GL depth range)\n";
}

// The residuals and the points left out.
void WriteResiduals(const FitResult& fit, const std::vector<std::string>& ids, std::ostream& out) {
  const int n = static_cast<int>(fit.residuals_px.size());
  out << "residuals: rms " << Format("%.3f", fit.rms_px) << " px, median "
      << Format("%.3f", fit.median_px) << " px, max " << Format("%.3f", fit.max_px) << " px\n";
  if (!fit.left_out.empty()) {
    out << "left out of the fit (found by " << fit.outlier_method << "): " << fit.left_out.size()
        << " of " << n << " points\n";
    constexpr size_t kListed = 20;
    for (size_t j = 0; j < std::min(kListed, fit.left_out.size()); ++j) {
      const LeftOutPoint& p = fit.left_out[j];
      out << "  " << PointName(ids, p.index) << " is "
          << (std::isfinite(p.residual_px)
                  ? Format("%.3g", p.residual_px) + " px from where the camera puts it"
                  : std::string("behind the camera (it has no pixel there)"));
      if (p.rms_with_px > 0.0) {
        out << "; with it the rms would be "
            << (std::isfinite(p.rms_with_px) ? Format("%.3g", p.rms_with_px) + " px"
                                             : std::string("infinite (no camera fits it)"))
            << ", without it " << Format("%.3g", fit.rms_px) << " px";
      }
      out << "\n";
    }
    if (fit.left_out.size() > kListed) {
      out << "  ... and " << fit.left_out.size() - kListed << " more (all in the camera file)\n";
    }
  } else if (!fit.outliers.empty()) {
    out << "outliers (RANSAC, left out of the fit): " << fit.outliers.size() << ":";
    for (const int i : fit.outliers) out << " " << PointName(ids, i);
    out << "\n";
  }
}

}  // namespace

std::string FitSummaryText(const FitResult& fit, const std::vector<std::string>& ids, int worst) {
  std::ostringstream out;
  WriteModel(fit, out);
  WriteUncertainty(fit, out);
  WriteCamera(fit, out);
  WriteResiduals(fit, ids, out);
  if (fit.consistency.checked) out << "check: " << fit.consistency.summary << "\n";
  if (fit.determination.checked) out << "determination: " << fit.determination.summary << "\n";
  if (fit.reliability.checked) out << "reliability: " << fit.reliability.summary << "\n";
  if (fit.linearity.checked) out << "linearity: " << LinearityText(fit.linearity) << "\n";
  out << "worst points:";
  const std::vector<int> order = WorstFirst(fit);
  for (int i = 0; i < std::min(worst, static_cast<int>(order.size())); ++i) {
    const int index = order[i];
    out << " " << PointName(ids, index)
        << " (" << Format("%.2f", fit.residuals_px[index].norm()) << " px)";
  }
  out << "\n";
  out << "time: " << Format("%.3f", fit.time_ms) << " ms, " << fit.iterations << " iterations of "
      << fit.refiner << " (" << fit.termination << "), Jacobian condition " << Format("%.3g", fit.jacobian_condition)
      << "\n";
  return out.str();
}

std::string FitTraceText(const FitResult& fit) {
  std::ostringstream out;
  out << "iteration  elapsed_us  rms_px\n";
  for (const TraceEntry& e : fit.trace) {
    char line[96];
    std::snprintf(line, sizeof line, "%9d  %10.1f  %.9g\n", e.iteration, e.elapsed_us, e.rms_px);
    out << line;
  }
  return out.str();
}

}  // namespace camproj

// bench --memory (memory.h).
#include "memory.h"

#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "camproj/fit.h"
#include "camproj/model_select.h"
#include "camproj/synth.h"
#include "common.h"
#include "point_counts.h"

namespace camproj {
namespace bench {
namespace {

const char* kUsage =
    "bench --memory: the fit's memory per point.\n"
    "\n"
    "Usage: bench --memory [--n N,N,...] [--out DIR]\n"
    "\n"
    "For each N, in a child process: a clean scene (SynthesizeScene cloud, 1920x1080, fovy 45\n"
    "deg, sigma 0.5 px), the peak resident set reset (/proc/self/clear_refs), one fit, and the\n"
    "peak minus the resident set before it: what the fit held on top of its input (points and\n"
    "pixels, 40 bytes a point). For FitCameraAuto with default options (what `camproj fit`\n"
    "runs) and FitCamera with default options.\n"
    "\n"
    "  --n N,N,...  point counts (default 10000,100000,400000)\n"
    "  --out DIR    also write DIR/memory.md\n"
    "\n"
    "Example:\n"
    "  bench --memory --out docs/bench    (what scripts/bench_memory.sh runs)\n";

// A field of /proc/self/status in kB ("VmRSS", "VmHWM"); -1 if it is not there.
long StatusKb(const std::string& field) {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line)) {
    if (line.compare(0, field.size() + 1, field + ":") == 0) {
      return std::atol(line.c_str() + field.size() + 1);
    }
  }
  return -1;
}

enum class Path { kDefault, kOneFit };

const char* Name(Path path) {
  return path == Path::kDefault ? "default (FitCameraAuto)" : "one fit (FitCamera, default options)";
}

struct Measurement {
  long held_kb = -1;  // peak resident set during the fit minus the resident set before it
  double seconds = 0.0;
  std::string outcome;  // the model, or "refused: ..."
};

// In a child: the scene, the reset, the fit; the numbers come back through a pipe as one line
// "held_kb seconds outcome".
Measurement Measure(Path path, int n) {
  int fds[2];
  if (pipe(fds) != 0) throw std::runtime_error("pipe failed");
  const pid_t child = fork();
  if (child < 0) throw std::runtime_error("fork failed");
  if (child == 0) {
    close(fds[0]);
    std::string line = "-1 0 measurement failed";
    try {
      SynthOptions synth;
      synth.seed = 1;
      synth.num_points = n;
      synth.object = SynthObject::kCloud;
      synth.image_size = ImageSize{1920, 1080};
      synth.fovy_deg = 45.0;
      synth.noise_px = 0.5;
      std::vector<Eigen::Vector3d> points;
      std::vector<Eigen::Vector2d> pixels;
      {
        SynthScene scene = SynthesizeScene(synth);
        points = std::move(scene.correspondences.points_in_world);
        pixels = std::move(scene.correspondences.pixels);
      }
      std::ofstream("/proc/self/clear_refs") << "5";
      const long before_kb = StatusKb("VmRSS");
      const auto start = std::chrono::steady_clock::now();
      std::string outcome;
      try {
        outcome = path == Path::kDefault
                      ? FitCameraAuto(points, pixels, synth.image_size).model
                      : FitCamera(points, pixels, synth.image_size, FitOptions()).model;
      } catch (const std::exception& e) {
        outcome = std::string("refused: ") + e.what();
      }
      const double seconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      const long peak_kb = StatusKb("VmHWM");
      if (before_kb >= 0 && peak_kb >= 0) {
        line = std::to_string(peak_kb - before_kb) + " " + std::to_string(seconds) + " " + outcome;
      }
    } catch (const std::exception& e) {
      line = std::string("-1 0 ") + e.what();
    }
    line += "\n";
    if (write(fds[1], line.data(), line.size()) < 0) _exit(2);
    _exit(0);
  }
  close(fds[1]);
  std::string text;
  char buffer[512];
  for (ssize_t got; (got = read(fds[0], buffer, sizeof buffer)) > 0;) text.append(buffer, got);
  close(fds[0]);
  int status = 0;
  waitpid(child, &status, 0);
  Measurement m;
  std::istringstream in(text);
  in >> m.held_kb >> m.seconds;
  std::getline(in >> std::ws, m.outcome);
  return m;
}

}  // namespace

int MemoryMain(int argc, char** argv) {
  std::vector<int> counts = {10000, 100000, 400000};
  std::string out_dir;
  std::string command = "bench --memory";
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::cerr << "bench: " << arg << " needs a value\n" << kUsage;
        std::exit(1);
      }
      command += " " + arg + " " + argv[i + 1];
      return argv[++i];
    };
    if (arg == "--memory") continue;
    if (arg == "-h" || arg == "--help") {
      std::cout << kUsage;
      return 0;
    } else if (arg == "--n") {
      if (!ParsePointCounts(value(), &counts)) return 1;
    } else if (arg == "--out") {
      out_dir = value();
    } else {
      std::cerr << "bench: unknown argument " << arg << "\n" << kUsage;
      return 1;
    }
  }
#ifndef NDEBUG
  std::cerr << "bench --memory: warning: assertions are on (not a Release build)\n";
#endif
  std::ostringstream table;
  table << "| fit | N | held MB | bytes per point | seconds | answer |\n"
        << "|---|---:|---:|---:|---:|---|\n";
  std::ostringstream slopes;
  int failed = 0;
  for (const Path path : {Path::kDefault, Path::kOneFit}) {
    std::vector<Measurement> rows;
    for (const int n : counts) {
      const Measurement m = Measure(path, n);
      if (m.held_kb < 0) ++failed;
      rows.push_back(m);
      table << "| " << Name(path) << " | " << n << " | " << Format(m.held_kb / 1024.0, "%.1f")
            << " | " << Format(1024.0 * m.held_kb / n, "%.0f") << " | "
            << Format(m.seconds, "%.2f") << " | " << m.outcome.substr(0, 60) << " |\n";
    }
    if (counts.size() >= 2) {
      // The slope between the smallest and the largest N: the fixed part cancels.
      const double slope = 1024.0 * (rows.back().held_kb - rows.front().held_kb) /
                           (counts.back() - counts.front());
      slopes << "- " << Name(path) << ": **" << Format(slope, "%.0f") << " bytes per point** ("
             << counts.front() << " to " << counts.back() << " points), plus the input's 40\n";
    }
  }
  std::time_t now = std::time(nullptr);
  char date[64];
  std::strftime(date, sizeof date, "%Y-%m-%d %H:%M:%S UTC", std::gmtime(&now));
  std::ostringstream report;
  report << "# Memory per point of the fit\n\n"
         << "Generated by `" << command << "` (apps/bench/memory.cc; `bash "
         << "scripts/bench_memory.sh` reruns it). Do not edit by hand.\n\n"
         << "| | |\n|---|---|\n"
         << "| command | `" << command << "` |\n"
         << "| git | " << GitDescription() << " |\n"
         << "| date | " << date << " |\n"
         << "| load average | " << LoadAverage() << " at the end (1, 5, 15 min) |\n\n"
         << "Held: the peak resident set during one fit minus the resident set before it (a child\n"
         << "process per row; the peak reset through /proc/self/clear_refs), i.e. what the fit\n"
         << "needs on top of its input, the points and pixels (24 + 16 bytes a point). Clean\n"
         << "scenes (SynthesizeScene cloud, 1920x1080, fovy 45 deg, sigma 0.5 px, seed 1).\n\n"
         << table.str() << "\n"
         << slopes.str();
  std::cout << report.str();
  if (!out_dir.empty()) {
    std::filesystem::create_directories(out_dir);
    std::ofstream(out_dir + "/memory.md") << report.str();
  }
  if (failed > 0) {
    std::cerr << "bench --memory: " << failed << " measurement(s) failed\n";
    return 2;
  }
  return 0;
}

}  // namespace bench
}  // namespace camproj

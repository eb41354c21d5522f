// bench --memory: the fit's memory per point. For each N, a child process synthesizes a clean
// scene (camproj::SynthesizeScene cloud, 1920x1080, fovy 45 deg, sigma 0.5 px), resets its peak
// resident set (writing 5 to /proc/self/clear_refs resets VmHWM to the current VmRSS), runs one
// fit and reports VmHWM - VmRSS: the most memory the fit itself held on top of its input (the
// points and pixels: 40 bytes a point, counted separately). Two fits: what `camproj fit` runs
// (FitCameraAuto, default options) and one FitCamera with default options.
// A child per measurement, so that no earlier fit's freed memory is reused by the next.
#ifndef CAMPROJ_APPS_BENCH_MEMORY_H_
#define CAMPROJ_APPS_BENCH_MEMORY_H_

namespace camproj {
namespace bench {

// `bench --memory [--n N,N,...] [--out DIR]`; argv as main's (the --memory flag may appear
// anywhere). Returns the exit status: 0 ok, 1 usage, 2 a measurement failed (Linux only: it
// reads /proc/self/status).
int MemoryMain(int argc, char** argv);

}  // namespace bench
}  // namespace camproj

#endif  // CAMPROJ_APPS_BENCH_MEMORY_H_

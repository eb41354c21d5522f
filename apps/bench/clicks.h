// bench --clicks: the click benchmark of the default fitting path (FitCameraAuto with default
// AutoFitOptions, what `camproj fit POINTS.csv --image-size WxH` runs) on seeded
// projection-mapping scenes clicked as a user would click them: a few box corners with rounded,
// noisy pixels, a mis-click, a mirrored world model, many points with outliers. Each answer is
// scored by how far it projects model points the fit never saw from where the true projector
// puts them. Generator, methods and columns: the header of the clicks.md it writes.
#ifndef CAMPROJ_APPS_BENCH_CLICKS_H_
#define CAMPROJ_APPS_BENCH_CLICKS_H_

namespace camproj {
namespace bench {

// `bench --clicks [--quick] [--out DIR] [--scenes N]`; argv as main's (the --clicks flag may
// appear anywhere). Returns the exit status: 0 ok; 1 usage, or with --quick a silent failure of
// the default path or an exception other than SceneError from a camproj fit; 2 error (e.g. the
// output cannot be written).
int ClicksMain(int argc, char** argv);

}  // namespace bench
}  // namespace camproj

#endif  // CAMPROJ_APPS_BENCH_CLICKS_H_

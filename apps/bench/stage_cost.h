// bench --stage-cost: the default path's cost on clean scenes. FitCameraAuto with default
// AutoFitOptions (what `camproj fit POINTS.csv --image-size WxH` runs) on the bench's clean
// scenes: camproj::SynthesizeScene clouds, 1920x1080, fovy 45 deg, sigma 0.5 px, a centred camera
// and a projector (principal point at the bottom edge), seeds 1..K. Prints per N the scenes, the
// refusals and the median wall time per fit. Instruction counts per fit and per stage come from
// running it under callgrind (scripts/bench_stage_cost.sh, docs/bench/stage_cost.md): the
// machines are shared, wall time is the secondary number.
//
// Uses only the public API that FitCameraAuto had before the default path's rewrite
// (model_select.h, synth.h), so the same scenes can be fitted by an older library: compiled with
// -DCAMPROJ_STAGE_COST_MAIN, stage_cost.cc is a program of its own (scripts/bench_stage_cost.sh
// --baseline REV).
#ifndef CAMPROJ_APPS_BENCH_STAGE_COST_H_
#define CAMPROJ_APPS_BENCH_STAGE_COST_H_

namespace camproj {
namespace bench {

// `bench --stage-cost [--n N,N,...] [--seeds K]`; argv as main's (the --stage-cost flag may
// appear anywhere). Returns the exit status: 0 ok, 1 usage.
int StageCostMain(int argc, char** argv);

}  // namespace bench
}  // namespace camproj

#endif  // CAMPROJ_APPS_BENCH_STAGE_COST_H_

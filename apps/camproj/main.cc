// camproj: the command line. Each subcommand parses, reads, calls the library and prints or
// writes (one file per subcommand). Exit codes: 0 ok, 1 usage, 2 bad input, 3 the scene cannot
// determine the requested camera.
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <new>
#include <vector>

#include "camproj/file_io.h"
#include "camproj/fit.h"
#include "camproj/library_logging.h"
#include "camproj/terminal_text.h"
#include "camproj_git_revision.h"
#include "cli.h"

namespace {

using namespace camproj::cli;

// The command's exit code once its standard output is flushed and closed: a failed write there
// (a full disk behind `>`, a closed descriptor) is reported and exits 2 where the command would
// have exited 0, so that a truncated output never looks like a success.
int FinishStandardOutput(int code) {
  std::cout.flush();
  const bool written = std::cout.good() && std::fflush(stdout) == 0 && !std::ferror(stdout);
  const int error = errno;
  // Closed explicitly: a write error a file system reports only on close (NFS) is caught too.
  // EBADF there, after every write succeeded, is a descriptor closed by the caller (`>&-`) that
  // nothing was written to: not an error (as GNU's close_stdout).
  const bool closed = std::fclose(stdout) == 0 || (written && errno == EBADF);
  if (written && closed) return code;
  std::cerr << "camproj: error: cannot write the standard output: "
            << std::strerror(written ? errno : error) << '\n';
  return code == kExitOk ? kExitBadInput : code;
}

int Run(int argc, char** argv) {
  CLI::App app{
      "camproj: make an OpenGL camera see exactly what a real camera or projector sees.\n\n"
      "Fit a camera to 2D-3D correspondences, export it as OpenGL / glm / OpenCV / COLMAP /\n"
      "three.js matrices, project points, convert between intrinsics, frustum and projection\n"
      "matrices, draw a fit over its image (overlay) or as a 3D page (view). Pixels follow\n"
      "OpenCV's convention ((0,0) is the centre of the top-left pixel)\n"
      "unless --pixel-origin corner; every convention is in docs/conventions.md.\n\n"
      "Exit codes: 0 ok, 1 usage, 2 bad input (names the file, line and field), 3 the points\n"
      "cannot determine the requested camera (says why and what to fix).\n\n"
      "Example:\n"
      "  camproj fit data/projector/points.csv --image-size 1920x1080 -o camera.json\n"
      "  camproj export camera.json --to gl",
      "camproj"};
  app.require_subcommand(1);
  // Root options (--verbose) may also follow the subcommand.
  app.fallthrough(true);
  app.set_version_flag("--version", "camproj " CAMPROJ_VERSION " (git " CAMPROJ_GIT_REVISION ")");
  bool verbose = false;
  app.add_flag("--verbose", verbose,
               "also show the log lines of the libraries camproj calls (Ceres/glog, OpenCV)");
  const std::vector<Command> commands = {AddFitCommand(app),     AddExportCommand(app),
                                         AddProjectCommand(app), AddConvertCommand(app),
                                         AddSynthCommand(app),   AddOverlayCommand(app),
                                         AddViewCommand(app),
                                         AddCalibrateCommand(app)};
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? kExitOk : kExitUsage;
  }
  camproj::InstallTemporaryFileCleanup();
  camproj::SetLibraryLogging(verbose);
  // Which command is running: a refusal says what it could not do.
  const char* refused = "fit";
  try {
    for (const Command& command : commands) {
      if (!*command.app) continue;
      if (command.app->get_name() == "calibrate") refused = "calibrate";
      return command.run();
    }
  } catch (const UsageError& e) {
    std::cerr << "camproj: usage: " << camproj::TerminalSafe(e.what()) << "\n(see camproj --help)\n";
    return kExitUsage;
  } catch (const camproj::SceneError& e) {
    // What to do on a line of its own, where the refusal says it apart from why.
    std::cerr << "camproj: cannot " << refused << ": " << camproj::TerminalSafe(e.why()) << '\n';
    const std::string fix = e.fix();
    if (!fix.empty()) std::cerr << "camproj: to fix: " << camproj::TerminalSafe(fix) << '\n';
    return kExitScene;
  } catch (const std::bad_alloc&) {
    // What a command builds (an export, a picture) did not fit: said in words, not as the type.
    std::cerr << "camproj: error: out of memory: what this command builds does not fit in the "
                 "memory this process may use (see ulimit -v)\n";
    return kExitBadInput;
  } catch (const std::exception& e) {
    // InputError (a file), std::invalid_argument (a value the library refused), or anything
    // else a library call threw: bad input, never an abort.
    std::cerr << "camproj: error: " << camproj::TerminalSafe(e.what()) << '\n';
    return kExitBadInput;
  }
  return kExitUsage;
}

}  // namespace

int main(int argc, char** argv) { return FinishStandardOutput(Run(argc, argv)); }

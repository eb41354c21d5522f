// Shared pieces of the camproj command line: exit codes, value parsing, subcommand registration.
#ifndef CAMPROJ_APPS_CLI_H_
#define CAMPROJ_APPS_CLI_H_

#include <functional>
#include <string>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>

#include "camproj/conventions.h"

namespace camproj::cli {

// Documented in README.md and `camproj --help`.
constexpr int kExitOk = 0;
constexpr int kExitUsage = 1;
constexpr int kExitBadInput = 2;
constexpr int kExitScene = 3;

// A bad command-line value: exit code 1 with the message.
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// "1920x1080" -> {1920, 1080}; throws UsageError naming `option`.
ImageSize ParseImageSize(const std::string& text, const std::string& option);

// "a,b,c" -> exactly `count` finite numbers; throws UsageError naming `option`.
std::vector<double> ParseNumbers(const std::string& text, size_t count, const std::string& option);

// Checks of a floating-point option's value, for CLI::Option::check: a finite number (what
// ParseNumbers accepts), and above 0 or at least 0. CLI::PositiveNumber and NonNegativeNumber let
// NaN through (a NaN --focal or --sigma was then taken as not given) and print the largest
// double in full in their message. CLI11 prefixes the option's name to the message; the value is
// refused with exit 1 before anything runs.
const CLI::Validator& FiniteNumber();
const CLI::Validator& PositiveFinite();
const CLI::Validator& NonNegativeFinite();

// RequireDistinctOutputs (file_io.h) on the outputs (option, path), as a UsageError: the second
// write would destroy the first. Call it before any work.
void RequireDistinctOptionOutputs(const std::vector<std::pair<std::string, std::string>>& outputs);

// The pixel convention of a command that reads or prints pixels beside a camera file: the
// --pixel-origin `option`'s `value` where it was given; else its default, kCenter, with a note on
// stderr where the camera file (`camera_path`) states its cx, cy in the corner convention: a user
// who fitted with --pixel-origin corner and leaves it off here would see each point 0.5 px off
// along u and v. `pixels` says what the convention is for ("points.csv's pixels are read").
PixelOrigin PixelOriginOfOption(const CLI::Option* option, const std::string& value,
                                PixelOrigin camera_file_origin, const std::string& camera_path,
                                const std::string& pixels);

// Files named on the command line, a folder standing for its *.csv files (sorted); throws
// UsageError for a folder without any.
std::vector<std::string> ExpandInputs(const std::vector<std::string>& paths);

// A registered subcommand: Run() is called when it was selected.
struct Command {
  CLI::App* app = nullptr;
  std::function<int()> run;
};

Command AddFitCommand(CLI::App& root);
Command AddExportCommand(CLI::App& root);
Command AddProjectCommand(CLI::App& root);
Command AddConvertCommand(CLI::App& root);
Command AddSynthCommand(CLI::App& root);
Command AddOverlayCommand(CLI::App& root);
Command AddViewCommand(CLI::App& root);
Command AddCalibrateCommand(CLI::App& root);

}  // namespace camproj::cli

#endif  // CAMPROJ_APPS_CLI_H_

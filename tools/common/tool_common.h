#pragma once
// What every pcl_ddg_* tool shares: PCL-style single-dash options (unknown ones rejected), one-line
// errors ("pcl_ddg_x: error: ...") with exit codes 0 ok / 1 failure / 2 usage, and timing lines.
#include <pcl/console/time.h>
#include <pcl/exceptions.h>

#include <condition_variable>
#include <cstdint>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "pcl_ddg/exceptions.h"

namespace pcl_ddg {
namespace tools {

/** A command line that does not follow the tool's syntax (exit code 2). */
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/** check(), a library's pcl::BadArgumentException becoming a UsageError (exit 2, "see -help"). */
template <typename Check>
auto usage(Check&& check) {
  try {
    return check();
  } catch (const pcl::BadArgumentException& e) {
    throw UsageError(errorDescription(e));
  }
}

/** -h or -help was given: print the description and syntax, exit 0. */
class HelpRequested : public std::exception {};

/** -version or --version was given: print the tool's name and pcl_ddg's version, exit 0. */
class VersionRequested : public std::exception {};

class ToolArguments {
 public:
  /** Options taking a value and switches are given without the dash: {"k", "method"}; every
   *  tool also takes -input_dir and -output_dir (forEachInput). */
  ToolArguments(int argc, char** argv, const std::set<std::string>& value_options,
                const std::set<std::string>& switches);

  const std::vector<std::string>& positional() const { return positional_; }
  bool has(const std::string& option) const;
  std::optional<std::string> value(const std::string& option) const;
  std::string text(const std::string& option, const std::string& fallback) const;
  /** One of `choices`, or a UsageError naming them. */
  std::string choice(const std::string& option, const std::vector<std::string>& choices,
                     const std::string& fallback) const;
  double number(const std::string& option, double fallback) const;
  int integer(const std::string& option, int fallback) const;

 private:
  std::vector<std::string> positional_;
  std::map<std::string, std::string> values_;
  std::set<std::string> switches_;
};

/**
 * Runs process(input, output) on the command line's input and output files, or, with
 * -input_dir DIR -output_dir OUT (PCL's batch mode), on every .ply .obj .off .stl .vtk .pcd .las
 * file of DIR in name order, writing OUT/<stem>.<ext>: the input's extension if it is one of
 * output_extensions, else the first of them. An empty output_extensions means the tool writes no
 * file (no output argument, no -output_dir). In a batch one failure does not stop the others: its
 * error line is printed, a summary ends the run, and the result is 1 if any file failed.
 */
int forEachInput(
    const ToolArguments& args, const char* tool_name,
    const std::vector<std::string>& output_extensions,
    const std::function<void(const std::string& input, const std::string& output)>& process);

/**
 * Refuses, before anything is read, an output that would destroy an input or could not be
 * written: the same file as one of `inputs` (by device and inode, whatever the spelling, links
 * included; a UsageError), a folder, or one whose folder is missing or not writable
 * (std::runtime_error). forEachInput calls it for every output it is given.
 */
void checkOutputFile(const std::string& output, const std::vector<std::string>& inputs);

/**
 * Runs a tool body: prints the description and syntax on -h, and turns every exception into one
 * line on stderr and an exit code (a usage error: the line ends "(see -help)", exit 2). With
 * PCL_DDG_PEAK_MEMORY_FILE set in the environment, the process's peak resident memory (VmHWM,
 * KiB) is written to that file at the end.
 */
int runTool(const char* name, const char* description, const char* syntax,
            const std::function<int()>& body);

/** Prints "tool: error: message" as one line of its own on stderr (newlines in the message become
 *  spaces; an unfinished progress line is ended first). */
void printError(const char* tool_name, const std::string& message);

/** Prints "tool: warning: message" on a line of its own on stderr. */
void warn(const char* tool_name, const std::string& message);

/** A progress bar on stderr for long loops, drawn over the current Timer line, and only when
 *  stderr is a terminal (logs and pipes get the timing line alone). */
class ProgressBar {
 public:
  explicit ProgressBar(std::string label);
  void update(int done, int total);
  /** Restores the label, so that the Timer's "[done, ...]" follows it. */
  void finish();

 private:
  std::string label_;
  bool enabled_;
  bool drawn_ = false;
};

/**
 * Prints "> Loading x [done, 12 ms : 35947 points]" lines, as PCL's tools do. On a terminal the
 * label appears at once (the user sees what is running), and a phase that takes longer than 2 s
 * shows its running time after it, updated every second (PCL_DDG_PROGRESS_AFTER_MS changes the
 * delay); elsewhere (logs, pipes, tests) the whole line is written by done(), so that a failure
 * leaves exactly one line: the error.
 */
class Timer {
 public:
  explicit Timer(std::string what);
  ~Timer();
  Timer(const Timer&) = delete;
  Timer& operator=(const Timer&) = delete;
  void done(std::size_t points);

 private:
  void showElapsedTime();
  void stopTicker();

  std::string label_;
  pcl::console::TicToc clock_;
  std::thread ticker_;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool finished_ = false;
};

}  // namespace tools
}  // namespace pcl_ddg

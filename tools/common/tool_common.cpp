#include "common/tool_common.h"

#include <malloc.h>
#include <pcl/exceptions.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <utility>

#include "common/huge_pages.h"
#include "pcl_ddg/exceptions.h"
#include "pcl_ddg/io/atomic_file.h"
#include "pcl_ddg/io/mesh_io.h"
#include "pcl_ddg/operators/sparse_cholesky.h"
#include "pcl_ddg/version.h"

namespace pcl_ddg {
namespace tools {
namespace {

// Whether stderr holds a line that has not been ended yet (a Timer label or a progress bar), and
// what it shows. Guarded by stderrMutex() where a Timer's ticker may draw at the same time.
struct OpenLine {
  bool open = false;
  std::string label;
  bool ticking = false;  ///< a Timer's running time follows the label
  bool bar = false;      ///< a ProgressBar owns the line
};

std::mutex& stderrMutex() {
  static std::mutex mutex;
  return mutex;
}
OpenLine& openLine() {
  static OpenLine line;
  return line;
}

bool stderrIsTerminal() {
  return isatty(fileno(stderr)) != 0;
}

void endOpenLine() {
  if (openLine().open) std::fputc('\n', stderr);
  openLine().open = openLine().ticking = openLine().bar = false;
}

void printLabel(const std::string& label) {
  pcl::console::print_highlight(stderr, "%s ", label.c_str());
  openLine() = {true, label, false, false};
}

std::chrono::milliseconds progressDelay() {
  const char* text = std::getenv("PCL_DDG_PROGRESS_AFTER_MS");
  return std::chrono::milliseconds(text ? std::max(0L, std::atol(text)) : 2000L);
}

bool isOption(const std::string& arg) {
  // "-k" is an option; "-1.5" is a (negative) number.
  return arg.size() > 1 && arg[0] == '-' && !std::isdigit(static_cast<unsigned char>(arg[1])) &&
         arg[1] != '.';
}

}  // namespace

ToolArguments::ToolArguments(int argc, char** argv, const std::set<std::string>& value_options,
                             const std::set<std::string>& switches) {
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (!isOption(arg)) {
      positional_.push_back(arg);
      continue;
    }
    const std::string name = arg.substr(arg.find_first_not_of('-'));
    if (name == "h" || name == "help") {
      throw HelpRequested();
    } else if (name == "version") {
      throw VersionRequested();
    } else if (value_options.count(name) || name == "input_dir" || name == "output_dir") {
      if (i + 1 >= argc) throw UsageError("option -" + name + " needs a value");
      values_[name] = argv[++i];
    } else if (switches.count(name)) {
      switches_.insert(name);
    } else {
      throw UsageError("unknown option " + arg);
    }
  }
}

bool ToolArguments::has(const std::string& option) const {
  return switches_.count(option) > 0 || values_.count(option) > 0;
}

std::optional<std::string> ToolArguments::value(const std::string& option) const {
  const auto it = values_.find(option);
  if (it == values_.end()) return std::nullopt;
  return it->second;
}

std::string ToolArguments::text(const std::string& option, const std::string& fallback) const {
  return value(option).value_or(fallback);
}

std::string ToolArguments::choice(const std::string& option,
                                  const std::vector<std::string>& choices,
                                  const std::string& fallback) const {
  const std::string chosen = text(option, fallback);
  for (const auto& c : choices) {
    if (c == chosen) return chosen;
  }
  std::string list;
  for (const auto& c : choices) list += (list.empty() ? "" : "|") + c;
  throw UsageError("-" + option + " must be one of " + list + ", not '" + chosen + "'");
}

double ToolArguments::number(const std::string& option, double fallback) const {
  const auto v = value(option);
  if (!v) return fallback;
  char* end = nullptr;
  const double x = std::strtod(v->c_str(), &end);
  if (end == v->c_str() || *end != '\0' || !std::isfinite(x)) {
    throw UsageError("-" + option + " needs a number, not '" + *v + "'");
  }
  return x;
}

int ToolArguments::integer(const std::string& option, int fallback) const {
  const auto v = value(option);
  if (!v) return fallback;
  char* end = nullptr;
  const long x = std::strtol(v->c_str(), &end, 10);
  if (end == v->c_str() || *end != '\0' || x < -1000000000L || x > 1000000000L) {
    throw UsageError("-" + option + " needs an integer, not '" + *v + "'");
  }
  return static_cast<int>(x);
}

namespace {

const char* const kCommonHelp =
    "Every tool but the viewer also takes:\n"
    "         -input_dir DIR [-output_dir OUT]  every .ply .obj .off .stl .vtk .pcd .las .laz\n"
    "                  file of DIR (PCL's batch mode; outputs OUT/<name>.<ext>, a failure does\n"
    "                  not stop the others)\n"
    "         -h, -help  this text;  --version  pcl_ddg's version\n";

const char* const kReadableExtensions[] = {"ply", "obj", "off", "stl", "vtk", "pcd", "las", "laz"};

std::string extensionList(const std::vector<std::string>& extensions) {
  std::string list;
  for (const auto& e : extensions) list += (list.empty() ? "." : " or .") + e;
  return list;
}

std::vector<std::string> batchInputs(const std::string& folder) {
  std::error_code error;
  if (!std::filesystem::is_directory(folder, error))
    throw UsageError("-input_dir " + folder + " is not a folder");
  std::vector<std::string> inputs;
  for (const auto& entry : std::filesystem::directory_iterator(folder, error)) {
    const std::string ext = fileExtension(entry.path().string());
    if (entry.is_regular_file(error) &&
        std::find(std::begin(kReadableExtensions), std::end(kReadableExtensions), ext) !=
            std::end(kReadableExtensions))
      inputs.push_back(entry.path().string());
  }
  if (error) throw std::runtime_error("cannot list " + folder + ": " + error.message());
  if (inputs.empty())
    throw std::runtime_error(folder + " holds no .ply .obj .off .stl .vtk .pcd .las or .laz file");
  std::sort(inputs.begin(), inputs.end());
  return inputs;
}

}  // namespace

void checkOutputFile(const std::string& output, const std::vector<std::string>& inputs) {
  namespace fs = std::filesystem;
  std::error_code error;
  // Identity, not spelling: equivalent() compares device and inode after following symbolic
  // links, so hard links and other spellings of an input are caught too.
  if (fs::exists(output, error)) {
    for (const std::string& input : inputs) {
      if (fs::equivalent(input, output, error))
        throw UsageError("the output " + output + " is the input " + input +
                         " (it would be replaced): choose another output name");
    }
    if (fs::is_directory(output, error)) throw UsageError("the output " + output + " is a folder");
  }
  fs::path folder = fs::path(output).parent_path();
  if (folder.empty()) folder = ".";
  if (!fs::is_directory(folder, error))
    throw std::runtime_error("the output folder " + folder.string() + " does not exist");
  // The output is written to a temporary file there and renamed: the folder must be writable.
  if (access(folder.c_str(), W_OK | X_OK) != 0)
    throw std::runtime_error("the output folder " + folder.string() + " is not writable");
}

int forEachInput(const ToolArguments& args, const char* tool_name,
                 const std::vector<std::string>& output_extensions,
                 const std::function<void(const std::string&, const std::string&)>& process) {
  const bool writes = !output_extensions.empty();
  if (!args.has("input_dir")) {
    if (args.has("output_dir")) throw UsageError("-output_dir needs -input_dir");
    const std::size_t expected = writes ? 2 : 1;
    if (args.positional().size() != expected)
      throw UsageError(writes ? "expected an input and an output file" : "expected one input file");
    const std::string& input = args.positional()[0];
    const std::string output = writes ? args.positional()[1] : "";
    if (writes && std::find(output_extensions.begin(), output_extensions.end(),
                            fileExtension(output)) == output_extensions.end())
      throw UsageError("the output must be " + extensionList(output_extensions));
    if (writes) checkOutputFile(output, {input});
    process(input, output);
    return 0;
  }
  if (!args.positional().empty())
    throw UsageError("-input_dir replaces the input and output files");
  if (writes != args.has("output_dir"))
    throw UsageError(writes ? "-input_dir needs -output_dir" : "this tool writes no files");
  const std::filesystem::path input_dir = *args.value("input_dir");
  const std::filesystem::path output_dir = writes ? *args.value("output_dir") : "";
  std::error_code error;
  if (writes && std::filesystem::equivalent(input_dir, output_dir, error))
    throw UsageError("-output_dir must differ from -input_dir (the inputs would be overwritten)");
  const std::vector<std::string> inputs = batchInputs(input_dir.string());
  std::vector<std::string> outputs(inputs.size());
  if (writes) {
    std::filesystem::create_directories(output_dir);
    std::map<std::string, std::string> written_by;
    for (std::size_t i = 0; i < inputs.size(); ++i) {
      const std::string ext = fileExtension(inputs[i]);
      const bool kept = std::find(output_extensions.begin(), output_extensions.end(), ext) !=
                        output_extensions.end();
      const std::filesystem::path name = std::filesystem::path(inputs[i]).stem();
      outputs[i] = (output_dir / name).string() + "." + (kept ? ext : output_extensions.front());
      const auto [it, fresh] = written_by.emplace(outputs[i], inputs[i]);
      if (!fresh)
        throw UsageError(it->second + " and " + inputs[i] + " would both write " + outputs[i]);
      checkOutputFile(outputs[i], inputs);
    }
  }

  std::vector<std::string> failed;
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    const std::string& input = inputs[i];
    const std::string& output = outputs[i];
    try {
      process(input, output);
    } catch (const std::exception& e) {
      const std::string message = errorDescription(e);
      // Loader errors name the file already; others get it in front.
      printError(tool_name,
                 message.find(input) == std::string::npos ? input + ": " + message : message);
      failed.push_back(std::filesystem::path(input).filename().string());
    }
  }
  std::string summary = std::to_string(inputs.size()) + " files, " +
                        std::to_string(inputs.size() - failed.size()) + " done, " +
                        std::to_string(failed.size()) + " failed";
  for (std::size_t i = 0; i < failed.size(); ++i) summary += (i ? ", " : ": ") + failed[i];
  endOpenLine();
  std::fprintf(stderr, "%s: %s\n", tool_name, summary.c_str());
  return failed.empty() ? 0 : 1;
}

namespace {

/** With PCL_DDG_PEAK_MEMORY_FILE set, writes this process's peak resident memory (VmHWM, in
 *  KiB) there: what tests and benchmarks measure. A parent's getrusage would not do: Linux
 *  carries ru_maxrss over an exec, so a forked child starts at the parent's size. */
void writePeakMemory() {
  const char* path = std::getenv("PCL_DDG_PEAK_MEMORY_FILE");
  if (path == nullptr || *path == '\0') return;
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);) {
    if (line.rfind("VmHWM:", 0) == 0) {
      std::ofstream(path) << std::strtol(line.c_str() + 6, nullptr, 10) << "\n";
      return;
    }
  }
}

/** A tool's arrays are tens of MB, allocated and freed phase after phase (file, positions, faces,
 *  topology, output). By glibc's defaults a block above 128 kB (rising only after one is freed)
 *  is mapped on its own and unmapped when freed, so the next one is faulted in again, page by
 *  page; and memory freed at the heap's top beyond 128 kB is handed back, to be faulted in again.
 *  Blocks up to 32 MiB (malloc's largest threshold) come from the heap, and up to 64 MiB of free
 *  top is kept: the bench mesh run (docs/benchmarks.md, "End to end") 206 -> 203 MB peak,
 *  79,843 -> 65,922 minor faults; a 5M-point LAS fit 371k -> 355k faults for +2 % peak. */
void keepFreedMemoryForReuse() {
  mallopt(M_MMAP_THRESHOLD, 32 << 20);
  mallopt(M_TRIM_THRESHOLD, 64 << 20);
}

int runBody(const char* name, const char* description, const char* syntax,
            const std::function<int()>& body) {
  try {
    return body();
  } catch (const HelpRequested&) {
    std::cout << description << "\nSyntax is: " << name << " " << syntax << "\n" << kCommonHelp;
    return 0;
  } catch (const VersionRequested&) {
    std::cout << name << " " << PCL_DDG_VERSION_STRING << "\n";
    return 0;
  } catch (const UsageError& e) {
    printError(name, std::string(e.what()) + " (see -help)");
    return 2;
  } catch (const pcl::BadArgumentException& e) {
    printError(name, errorDescription(e));
    return 2;
  } catch (const std::exception& e) {
    printError(name, errorDescription(e));
    return 1;
  } catch (...) {
    printError(name, "unknown internal error");
    return 1;
  }
}

}  // namespace

int runTool(const char* name, const char* description, const char* syntax,
            const std::function<int()>& body) {
  // A tool is the whole process: its global state is ours.
  restartOnHugePagesForLargeInputs();
  AtomicFile::removeUncommittedFilesOnInterrupt();  // Ctrl-C leaves no temporary behind
  keepFreedMemoryForReuse();
  tuneCholmodForLargeSystems();
  const int code = runBody(name, description, syntax, body);
  writePeakMemory();
  return code;
}

void printError(const char* tool_name, const std::string& message) {
  const std::lock_guard<std::mutex> lock(stderrMutex());
  endOpenLine();
  std::string line = message.empty() ? std::string("unknown error") : message;
  std::replace(line.begin(), line.end(), '\n', ' ');
  std::fprintf(stderr, "%s: error: %s\n", tool_name, line.c_str());
  std::fflush(stderr);
}

void warn(const char* tool_name, const std::string& message) {
  const std::lock_guard<std::mutex> lock(stderrMutex());
  endOpenLine();
  std::fprintf(stderr, "%s: warning: %s\n", tool_name, message.c_str());
}

ProgressBar::ProgressBar(std::string label)
    : label_(std::move(label)), enabled_(stderrIsTerminal()) {}

void ProgressBar::update(int done, int total) {
  if (!enabled_ || total < 2) return;
  const std::lock_guard<std::mutex> lock(stderrMutex());
  constexpr int kWidth = 30;
  const int filled = static_cast<int>(static_cast<long long>(kWidth) * done / total);
  std::fprintf(stderr, "\r%s [%s%s] %d/%d", label_.c_str(), std::string(filled, '#').c_str(),
               std::string(kWidth - filled, '.').c_str(), done, total);
  std::fflush(stderr);
  openLine().open = openLine().bar = true;
  drawn_ = true;
}

void ProgressBar::finish() {
  const std::lock_guard<std::mutex> lock(stderrMutex());
  if (drawn_) std::fprintf(stderr, "\r%s \033[K", label_.c_str());
  openLine().bar = false;
  drawn_ = false;
}

Timer::Timer(std::string what) : label_(std::move(what)) {
  clock_.tic();
  if (!stderrIsTerminal()) return;
  printLabel(label_);
  ticker_ = std::thread([this] { showElapsedTime(); });
}

Timer::~Timer() {
  stopTicker();
}

void Timer::stopTicker() {
  if (!ticker_.joinable()) return;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    finished_ = true;
  }
  wake_.notify_one();
  ticker_.join();
}

void Timer::showElapsedTime() {
  std::unique_lock<std::mutex> lock(mutex_);
  if (wake_.wait_for(lock, progressDelay(), [this] { return finished_; })) return;
  do {
    const std::lock_guard<std::mutex> out(stderrMutex());
    // Only over our own label: a warning or a progress bar since then owns the line.
    if (openLine().open && openLine().label == label_ && !openLine().bar) {
      std::fprintf(stderr, "\r");
      pcl::console::print_highlight(stderr, "%s ", label_.c_str());
      std::fprintf(stderr, "(%.0f s) ", clock_.toc() / 1000.0);
      std::fflush(stderr);
      openLine().ticking = true;
    }
  } while (!wake_.wait_for(lock, std::chrono::seconds(1), [this] { return finished_; }));
}

void Timer::done(std::size_t points) {
  stopTicker();
  const std::lock_guard<std::mutex> lock(stderrMutex());
  // Re-labelled when something else was printed since (or nothing was, off a terminal), or
  // when the running time follows the label.
  if (openLine().ticking && openLine().label == label_) {
    std::fprintf(stderr, "\r\033[K");
    printLabel(label_);
  } else if (!openLine().open || openLine().label != label_) {
    endOpenLine();
    printLabel(label_);
  }
  openLine().open = false;
  pcl::console::print_info(stderr, "[done, ");
  pcl::console::print_value(stderr, "%g", clock_.toc());
  pcl::console::print_info(stderr, " ms : ");
  pcl::console::print_value(stderr, "%zu", points);
  pcl::console::print_info(stderr, " points]\n");
}

}  // namespace tools
}  // namespace pcl_ddg

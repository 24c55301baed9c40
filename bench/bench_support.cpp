#include "bench_support.h"

#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace pcl_ddg {
namespace bench {
namespace {

std::vector<std::pair<std::string, std::string>>& extraRatios() {
  static std::vector<std::pair<std::string, std::string>> pairs;
  return pairs;
}

// Records the real time of every run (the median when run with --benchmark_repetitions, which a
// shared VM needs) while the console reporter prints as usual.
class RatioReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const Run& run : runs) {
      const bool median = run.run_type == Run::RT_Aggregate && run.aggregate_name == "median";
      if ((run.run_type == Run::RT_Iteration || median) && !run.error_occurred) {
        times_ms_[run.run_name.function_name] =
            run.GetAdjustedRealTime() * benchmark::GetTimeUnitMultiplier(benchmark::kMillisecond) /
            benchmark::GetTimeUnitMultiplier(run.time_unit);
      }
    }
  }
  void printRatios() const {
    std::printf("\n%-40s %12s %12s %8s\n", "operation", "ours (ms)", "baseline", "ratio");
    for (const auto& [name, ours] : times_ms_) {
      if (name.rfind("ours/", 0) != 0) continue;
      const std::string what = name.substr(5);
      const auto baseline = times_ms_.find("baseline/" + what);
      if (baseline == times_ms_.end()) {
        std::printf("%-40s %12.1f %12s %8s\n", what.c_str(), ours, "-", "-");
      } else {
        std::printf("%-40s %12.1f %12.1f %7.1fx\n", what.c_str(), ours, baseline->second,
                    baseline->second / ours);
      }
    }
    for (const auto& [ours, baseline] : extraRatios()) {
      const auto a = times_ms_.find(ours), b = times_ms_.find(baseline);
      if (a == times_ms_.end() || b == times_ms_.end()) continue;
      std::printf("%-40s %12.1f %12.1f  takes %.2fx the time of %s\n", ours.c_str(), a->second,
                  b->second, a->second / b->second, baseline.c_str());
    }
  }

 private:
  std::map<std::string, double> times_ms_;
};

}  // namespace

const BenchMesh& torusMesh(int around, int tube) {
  static std::map<std::pair<int, int>, std::unique_ptr<BenchMesh>> cache;
  auto& slot = cache[{around, tube}];
  if (slot) return *slot;
  slot = std::make_unique<BenchMesh>();
  BenchMesh& m = *slot;
  const double pi = 3.14159265358979323846;
  m.points.resize(3, static_cast<Eigen::Index>(around) * tube);
  for (int j = 0; j < tube; ++j) {
    for (int i = 0; i < around; ++i) {
      const double u = 2 * pi * i / around, v = 2 * pi * j / tube;
      m.points.col(j * around + i) << (1 + 0.4 * std::cos(v)) * std::cos(u),
          (1 + 0.4 * std::cos(v)) * std::sin(u), 0.4 * std::sin(v);
    }
  }
  m.triangles.resize(3, 2 * static_cast<Eigen::Index>(around) * tube);
  Eigen::Index t = 0;
  for (int j = 0; j < tube; ++j) {
    for (int i = 0; i < around; ++i) {
      const int a = j * around + i, b = j * around + (i + 1) % around;
      const int c = ((j + 1) % tube) * around + (i + 1) % around, d = ((j + 1) % tube) * around + i;
      m.triangles.col(t++) << a, b, c;
      m.triangles.col(t++) << a, c, d;
    }
  }
  return m;
}

void addRatio(const std::string& ours_name, const std::string& baseline_name) {
  extraRatios().emplace_back(ours_name, baseline_name);
}

int runWithRatios(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  RatioReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  reporter.printRatios();
  benchmark::Shutdown();
  return 0;
}

}  // namespace bench
}  // namespace pcl_ddg

// LAZ decode and encode speed (src/io/laz) on the LAS files given, in points per second, beside
// our own uncompressed LAS read of the same file. bench/bench_laz.py makes the files (5M points of
// format 3 and of format 7), runs this, and runs laz-perf (node) on the same LAZ in the same run.
//   bench_laz FILE.las [FILE.las ...] [--benchmark_* options]
#include <benchmark/benchmark.h>

#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "io/laz/laz_codec.h"
#include "pcl_ddg/io/mesh_io.h"

namespace {

std::string readBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

std::uint64_t pointCount(const std::string& las) {
  std::uint32_t legacy;
  std::memcpy(&legacy, las.data() + 107, 4);
  std::uint64_t count = legacy;
  if (las[25] >= 4) std::memcpy(&count, las.data() + 247, 8);
  return count;
}

struct Input {
  std::string path, las, laz;
  std::uint64_t points = 0;
};

void setRate(benchmark::State& state, std::uint64_t points) {
  state.counters["points/s"] = benchmark::Counter(static_cast<double>(points),
                                                  benchmark::Counter::kIsIterationInvariantRate);
}

void decode(benchmark::State& state, const Input* input) {
  const int threads = static_cast<int>(state.range(0));
  for (auto _ : state) benchmark::DoNotOptimize(pcl_ddg::detail::lazToLas(input->laz, threads));
  setRate(state, input->points);
}

void encode(benchmark::State& state, const Input* input) {
  for (auto _ : state) benchmark::DoNotOptimize(pcl_ddg::detail::lasToLaz(input->las));
  setRate(state, input->points);
}

void readLas(benchmark::State& state, const Input* input) {
  for (auto _ : state) benchmark::DoNotOptimize(pcl_ddg::readMeshFile(input->path));
  setRate(state, input->points);
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  std::vector<Input> inputs;
  for (int i = 1; i < argc; ++i) {
    Input in;
    in.path = argv[i];
    in.las = readBytes(in.path);
    in.laz = pcl_ddg::detail::lasToLaz(in.las);
    in.points = pointCount(in.las);
    inputs.push_back(std::move(in));
  }
  for (const Input& in : inputs) {
    benchmark::RegisterBenchmark(("laz_decode/" + in.path).c_str(), decode, &in)
        ->Arg(1)
        ->Arg(2)
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
    benchmark::RegisterBenchmark(("laz_encode/" + in.path).c_str(), encode, &in)
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
    benchmark::RegisterBenchmark(("las_read/" + in.path).c_str(), readLas, &in)
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
  }
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
}

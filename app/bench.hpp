#pragma once
#include <string>
#include <vector>

namespace loam {

struct BenchOptions {
  bool json = false;
  long steps = 200;
  std::vector<int> threads{1, 2};
  std::vector<std::string> scenes{"elastic_block_2d", "elastic_block_3d"};
  std::string update = "musl";
  std::vector<std::string> shapes{"linear"};  // "all": every registered shape function
  int repeat = 1;
  bool profile = false;
  std::string materials;  // non-empty: the stress-update benchmark ("all" or one material)
};

/// `loam bench`: fixed scenes, printed as one JSON object per run. Returns the exit code.
int run_bench(const BenchOptions& options);

/// `loam bench --materials`: stress-update cost per particle of each material plugin.
int run_material_bench(const BenchOptions& options);

/// The YAML of a benchmark scene (also used by tests to check the scenes are valid).
std::string bench_scene(const std::string& scene, const std::string& shape,
                        const std::string& update);

}  // namespace loam

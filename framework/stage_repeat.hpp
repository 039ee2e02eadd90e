#pragma once
// A stage that repeats with an increment (stages[].repeat, docs/stages.md "Repeated stages"):
// `repeat: {times: N, step: {key.path: increment}}` stands for N copies of the stage, named
// NAME_1 .. NAME_N, copy k (from 0) with each stepped value v + k * increment. The copies
// replace the stage in the list before validation, so a run with them is the run of the copied
// stages, to the bit.
#include <string>

#include <yaml-cpp/yaml.h>

#include "diagnostics.hpp"

namespace loam {

/// Expand every stages[].repeat of the run file's tree in place; a bad repeat is a located
/// error (its stage is then left as it is, without the repeat).
void expand_repeated_stages(YAML::Node root, const std::string& file, Diagnostics& diag);

}  // namespace loam

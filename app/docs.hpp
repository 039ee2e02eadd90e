#pragma once
// Plain-text and Markdown documentation generated from plugin and config schemas.
#include <string>

namespace loam {

/// `loam plugins [KIND]`: every plugin of a kind (or all kinds) with its parameters.
/// Returns false if the kind is unknown (the message lists the valid kinds).
bool print_plugins(const std::string& kind, bool markdown, std::string& out);
/// `loam schema`: the keys of a run file.
std::string print_config_schema(bool markdown);

}  // namespace loam

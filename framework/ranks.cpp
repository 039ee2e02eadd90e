#include "ranks.hpp"

#include <cstdio>

namespace loam {

std::string rank_tag(int rank) {
  char s[32];
  std::snprintf(s, sizeof s, "_r%04d", rank);
  return s;
}

RanksFactory& ranks_factory() {
  static RanksFactory factory;
  return factory;
}

}  // namespace loam

#include "ranks.hpp"

namespace loam {

RanksFactory& ranks_factory() {
  static RanksFactory factory;
  return factory;
}

}  // namespace loam

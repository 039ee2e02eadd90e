#include <catch2/catch.hpp>

#include "framework/registry.hpp"

TEST_CASE("every kind has plugins and every parameter is documented", "[registry]") {
  auto& reg = loam::Registry::instance();
  REQUIRE(reg.kinds().size() >= 8);
  for (const auto& k : reg.kinds()) {
    INFO("kind " << k.name);
    CHECK_FALSE(reg.names(k.name).empty());
    for (const auto& n : reg.names(k.name)) {
      const auto* info = reg.find(k.name, n);
      CHECK_FALSE(std::string(info->summary).empty());
      for (const auto& p : info->schema().params) {
        INFO(k.name << " " << n << "." << p.key);
        CHECK_FALSE(p.doc.empty());
        CHECK_FALSE(p.unit.empty());
      }
    }
  }
}

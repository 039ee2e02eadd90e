// Refactoring guard: particle frames of existing single-set scenes must stay bit-identical when
// the code is restructured without changing the physics (particle sets, shared step building
// blocks). Each scene runs a short stretch on 1 and on 2 threads, which must give the same bits
// (the scatter's slabs and their order do not depend on the thread count:
// framework/partition.hpp), and every dataset of its last particle frame is hashed (FNV-1a over
// the raw bytes, dataset names included). The expected hashes are in
// tests/data/frame_checksums.txt (each set of a two-set scene on its own line); why and by how
// much each was re-recorded is in the commit that did it.
// A change that alters the numbers on purpose (new physics, a fix) re-records them with
//   LOAM_RECORD_CHECKSUMS=1 build/loam_tests "particle frames*"
// and says so in its commit message.
#include <hdf5.h>

#include <catch2/catch.hpp>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <vector>

#include "cli.hpp"

namespace fs = std::filesystem;
using namespace loam_test;

namespace {

struct Scene {
  std::string name, config, overrides;
};

// A cross-section of what the core does: 2D single phase with Mohr-Coulomb, gimp and friction;
// 1D USL linear; 3D cpdi with damping; 2D two-phase with traction and drained face.
const std::vector<Scene> kScenes = {
    {"granular_collapse_gimp", "granular_collapse_2d.yaml",
     "--set shape_function.type=gimp --set time.end=0.03"},
    {"vibrating_bar_usl", "vibrating_bar.yaml",
     "--set scheme.update=usl --set time.end=2 --set output.fields=[velocity,stress,volume]"},
    {"elastic_column_3d_cpdi", "elastic_column_3d.yaml",
     "--set shape_function.type=cpdi --set time.end=0.004"},
    {"terzaghi_2d_two_phase", "seed001_terzaghi_2d.yaml", "--set time.end=0.01"},
    {"terzaghi_2d_two_phase_bspline2", "seed001_terzaghi_2d.yaml",
     "--set time.end=0.01 --set shape_function=bspline2"},
    {"terzaghi_2d_double_point", "terzaghi_double_point_2d.yaml", "--set time.end=0.01"},
    {"terzaghi_2d_double_point_bspline2", "terzaghi_double_point_2d.yaml",
     "--set time.end=0.01 --set shape_function=bspline2"},
};

void fnv1a(uint64_t& h, const void* data, size_t n) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 1099511628211ull;
}

herr_t hash_dataset(hid_t group, const char* name, const H5L_info_t*, void* acc) {
  uint64_t& h = *static_cast<uint64_t*>(acc);
  hid_t ds = H5Dopen2(group, name, H5P_DEFAULT);
  hid_t type = H5Dget_type(ds);
  const size_t bytes = size_t(H5Dget_storage_size(ds));
  std::vector<unsigned char> buf(bytes);
  if (bytes) H5Dread(ds, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf.data());
  fnv1a(h, name, std::strlen(name));
  fnv1a(h, buf.data(), buf.size());
  H5Tclose(type);
  H5Dclose(ds);
  return 0;
}

/// Hash of every dataset of an HDF5 file, in name order.
uint64_t hash_frame(const fs::path& file) {
  uint64_t h = 1469598103934665603ull;
  hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  REQUIRE(f >= 0);
  H5Literate(f, H5_INDEX_NAME, H5_ITER_INC, nullptr, hash_dataset, &h);
  H5Fclose(f);
  return h;
}

/// The newest regular frame (highest number, no label) of each particle set in a run directory,
/// by set name (the file name before its number: particles, solid, liquid).
std::map<std::string, fs::path> last_frames(const fs::path& dir) {
  std::map<std::string, fs::path> best;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string n = e.path().filename().string();
    if (e.path().extension() != ".h5" || n.find("_failed") != std::string::npos ||
        n.rfind("checkpoint_", 0) == 0)
      continue;
    const std::string set = n.substr(0, n.rfind('_'));
    if (!best.count(set) || n > best[set].filename().string()) best[set] = e.path();
  }
  return best;
}

std::map<std::string, std::string> read_expected(const fs::path& file) {
  std::map<std::string, std::string> m;
  std::ifstream in(file);
  for (std::string name, hash; in >> name >> hash;) m[name] = hash;
  return m;
}

}  // namespace

TEST_CASE("particle frames of existing scenes are bit-identical to the recorded ones",
          "[regression]") {
  const fs::path table = fs::path(LOAM_SOURCE_DIR) / "tests/data/frame_checksums.txt";
  const bool record = std::getenv("LOAM_RECORD_CHECKSUMS") != nullptr;
  const auto expected = read_expected(table);
  std::ostringstream recorded;
  for (const auto& s : kScenes) {
    std::map<std::string, std::string> one_thread;  // set name -> hash
    for (const int threads : {1, 2}) {
      TempDir dir("bitid_" + s.name);
      run_scene(s.config, dir.path, "--threads " + std::to_string(threads) + " " + s.overrides);
      const auto frames = last_frames(dir.path);
      REQUIRE(!frames.empty());
      for (const auto& [set, frame] : frames) {
        // One set keeps the scene's name; each set of a two-set scene gets its own line.
        const std::string name = frames.size() == 1 ? s.name : s.name + "_" + set;
        char hex[17];
        std::snprintf(hex, sizeof hex, "%016llx", (unsigned long long)hash_frame(frame));
        INFO(name << " on " << threads << " thread(s): last frame " << frame.filename().string()
                  << " hash " << hex);
        if (threads == 1) {
          one_thread[name] = hex;
          recorded << name << " " << hex << "\n";
        } else {
          CHECK(one_thread.at(name) == hex);  // the same bits on any number of threads
        }
        if (!record) {
          REQUIRE(expected.count(name) == 1);
          CHECK(expected.at(name) == hex);
        }
      }
    }
  }
  if (record) std::ofstream(table) << recorded.str();
}

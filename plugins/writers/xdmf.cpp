// ParaView output: per particle set, one HDF5 file per frame (<set>_NNNNNN.h5, e.g.
// particles_000003.h5) and one XDMF index (<set>.xdmf, a temporal collection of Polyvertex
// grids; the particle count may change from frame to frame). 2D/1D coordinates are padded to
// XYZ so that ParaView glyph filters work; D-component fields are written as 3-vectors.
// Every file is written under a temporary name and renamed when complete.
//
// Under mpirun (docs/parallel.md) each rank writes its own particles of a frame,
// <set>_NNNNNN_rRRRR.h5, and the first rank the index, in which each frame is a spatial
// collection of the ranks' pieces: ParaView opens it as one dataset per frame. With `grid`,
// each rank's piece of the first set also holds the grid nodes it owns, and the grid's frames
// are spatial collections of those.
#include <hdf5.h>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "framework/interrupt.hpp"
#include "framework/registry.hpp"
#include "framework/simulation.hpp"

namespace loam {

template <int D>
class Xdmf : public Writer<D> {
 public:
  static constexpr const char* name = "xdmf";
  static constexpr const char* summary = "HDF5 per frame + XDMF index, opens in ParaView";
  static Schema schema() {
    Schema s;
    s.boolean("grid", "also write the grid nodes with the scheme's nodal fields").def("false");
    return s;
  }
  explicit Xdmf(const Params& p) : with_grid_(p.flag("grid")) {}

  void open(const std::string& dir, Simulation<D>&, const std::vector<int>& fields) override {
    dir_ = dir;
    fields_ = fields;
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);  // failures are reported as WriteError
  }

  /// The frame list of every set (checkpoints: the index goes on after --resume).
  std::string state() const override {
    nlohmann::json j = nlohmann::json::array();
    for (const auto& set : frames_) {
      nlohmann::json js = nlohmann::json::array();
      for (const auto& f : set) {
        auto attrs = [](const std::vector<Attribute>& as) {
          nlohmann::json a = nlohmann::json::array();
          for (const auto& x : as) a.push_back({x.name, x.width, x.number_type});
          return a;
        };
        js.push_back({{"file", f.file},
                      {"time", f.time},
                      {"step", f.step},
                      {"n", f.n},
                      {"attributes", attrs(f.attributes)},
                      {"grid_nodes", f.grid_nodes},
                      {"grid_attributes", attrs(f.grid_attributes)}});
        if (!f.pieces.empty()) js.back()["pieces"] = f.pieces;
        if (!f.grid_pieces.empty()) js.back()["grid_pieces"] = f.grid_pieces;
      }
      j.push_back(js);
    }
    return j.dump();
  }
  void restore_state(const std::string& text) override {
    const auto j = nlohmann::json::parse(text);
    frames_.assign(j.size(), {});
    for (size_t s = 0; s < j.size(); ++s)
      for (const auto& f : j[s]) {
        auto attrs = [](const nlohmann::json& a) {
          std::vector<Attribute> as;
          for (const auto& x : a) as.push_back({x[0], x[1], x[2]});
          return as;
        };
        frames_[s].push_back(Frame{f["file"], f["time"], f["step"], f["n"], attrs(f["attributes"]),
                                   f["grid_nodes"], attrs(f["grid_attributes"]),
                                   f.value("pieces", std::vector<long>{}),
                                   f.value("grid_pieces", std::vector<long>{})});
      }
  }

  void write(Simulation<D>& sim, const std::string& label) override {
    frames_.resize(sim.sets.size());
    for (size_t s = 0; s < sim.sets.size(); ++s) write_set(sim, s, label);
  }

 private:
  struct Attribute {
    std::string name;
    int width;
    std::string number_type;
  };
  struct Frame {
    std::string file;
    double time;
    long step;
    size_t n;
    std::vector<Attribute> attributes;
    size_t grid_nodes = 0;
    std::vector<Attribute> grid_attributes;
    std::vector<long> pieces;       // under mpirun, each rank's particle count (first rank only)
    std::vector<long> grid_pieces;  // under mpirun, each rank's owned node count (first rank)
  };
  std::string dir_;
  std::vector<int> fields_;
  std::vector<std::vector<Frame>> frames_;  // per set
  bool with_grid_;
  bool ok_ = true;  // every dataset of the frame being written was written

  /// One frame of set s: <set>_NNNNNN[_label].h5 with the particles (and, in the first set's
  /// file, the grid), then the set's index <set>.xdmf.
  void write_set(Simulation<D>& sim, size_t s, const std::string& label) {
    const ParticleSet<D>& set = sim.sets[s];
    const Ranks<D>& ranks = *sim.ranks;
    char stem[128];
    std::snprintf(stem, sizeof stem, "%s_%06ld%s", set.name.c_str(), long(frames_[s].size()),
                  label.empty() ? "" : ("_" + label).c_str());
    if (!ranks.distributed()) {
      Frame fr = write_particles(sim, set, std::string(stem) + ".h5");
      frames_[s].push_back(fr);
      write_index(set.name, frames_[s], with_grid_ && s == 0);
      return;
    }
    // Every rank takes part in the gather even if its file failed, so that none waits forever;
    // the failure is reported after it (the runner stops all ranks).
    Frame fr;
    std::string error, failed_file;
    try {
      fr = write_particles(sim, set, std::string(stem) + ranks.file_tag() + ".h5");
    } catch (const WriteError& e) {
      error = e.what(), failed_file = e.file;
    }
    fr.file = stem;
    fr.pieces = ranks.gather(long(set.size()));
    const bool grid = with_grid_ && s == 0;
    if (grid) fr.grid_pieces = ranks.gather(long(fr.grid_nodes));
    if (!error.empty()) throw WriteError(failed_file, error);
    frames_[s].push_back(fr);
    if (ranks.root()) write_index(set.name, frames_[s], grid);
  }

  /// This process's particles of a set as the HDF5 file `name` in the directory.
  Frame write_particles(Simulation<D>& sim, const ParticleSet<D>& set, const std::string& name) {
    const Particles<D>& P = set.particles;
    const size_t n = P.size();
    std::filesystem::path file = std::filesystem::path(dir_) / name;
    std::filesystem::path tmp = file;
    tmp += ".tmp";
    const TemporaryFileGuard guard(tmp.string());  // a second signal removes it
    errno = 0;
    hid_t f = H5Fcreate(tmp.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    if (f < 0) fail(file, tmp);
    ok_ = true;
    Frame fr{name, sim.time, sim.step, n, {}, 0, {}, {}, {}};
    write_columns(f, "position", P, P.position, 3);
    std::vector<int> ids(n);
    for (size_t i = 0; i < n; ++i) ids[i] = int(P.id[i]);
    write_dataset(f, "id", ids.data(), n, 1, H5T_NATIVE_INT);
    fr.attributes.push_back({"id", 1, "Int"});
    for (int h : fields_) {
      if (!P.has(h)) continue;  // e.g. a material's state in a set without that material
      const FieldInfo& info = P.info(h);
      // Spatial vectors (components x, y, z) are padded to 3 for ParaView; in 1D a scalar field
      // also has D components, so the component names decide.
      const bool spatial =
          !info.component_names.empty() && info.component_names[0] == "x" && info.components == D;
      const int width = spatial ? 3 : info.components;
      write_columns(f, info.name, P, h, width);
      fr.attributes.push_back({info.name, width, "Float"});
    }
    if (with_grid_ && &set == &sim.sets[0]) write_grid(f, sim, fr);
    const bool closed = H5Fclose(f) >= 0;
    if (!ok_ || !closed) fail(file, tmp);
    std::filesystem::rename(tmp, file);
    return fr;
  }

  /// The frame's temporary file is removed and the failure reported (WriteError).
  [[noreturn]] static void fail(const std::filesystem::path& file,
                                const std::filesystem::path& tmp) {
    const std::string reason = WriteError::os_reason("HDF5 could not write the file");
    std::error_code ec;
    std::filesystem::remove(tmp, ec);
    throw WriteError(file.string(), reason);
  }

  void write_dataset(hid_t f, const std::string& name, const void* data, size_t n, int width,
                     hid_t type) {
    hsize_t dims[2] = {hsize_t(n), hsize_t(width)};
    hid_t space = H5Screate_simple(width == 1 ? 1 : 2, dims, nullptr);
    hid_t ds = H5Dcreate2(f, name.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    if (ds < 0 || (n > 0 && H5Dwrite(ds, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0))
      ok_ = false;
    if (ds >= 0) H5Dclose(ds);
    H5Sclose(space);
  }

  void write_columns(hid_t f, const std::string& name, const Particles<D>& P, int h, int width) {
    const size_t n = P.size();
    const int nc = P.info(h).components;
    std::vector<double> buf(n * size_t(width), 0.0);
    for (int c = 0; c < nc; ++c) {
      const double* col = P.col(h, c);
      for (size_t i = 0; i < n; ++i) buf[i * size_t(width) + size_t(c)] = col[i];
    }
    write_dataset(f, name, buf.data(), n, width, H5T_NATIVE_DOUBLE);
  }

  /// The grid's nodes with the scheme's nodal fields (grid_position, grid_<field>). Under
  /// mpirun each rank writes the nodes it owns (Ranks::owns_node: every node once over the
  /// ranks; every stored copy holds the whole grid's value after the step).
  void write_grid(hid_t f, Simulation<D>& sim, Frame& fr) {
    const auto& g = sim.grid;
    std::vector<size_t> nodes;
    for (size_t n = 0; n < g.num_nodes; ++n)
      if (!sim.ranks->distributed() || sim.ranks->owns_node(g, g.node_ijk(n))) nodes.push_back(n);
    const size_t count = nodes.size();
    std::vector<double> xyz(count * 3, 0.0);
    for (size_t k = 0; k < count; ++k)
      for (int d = 0; d < D; ++d) xyz[k * 3 + size_t(d)] = g.node_coord(nodes[k], d);
    write_dataset(f, "grid_position", xyz.data(), count, 3, H5T_NATIVE_DOUBLE);
    fr.grid_nodes = count;
    for (const auto& v : sim.scheme->grid_fields()) {
      const int width = v.components == D && D > 1 ? 3 : v.components;  // pad 2D vectors
      std::vector<double> buf(count * size_t(width), 0.0);
      for (size_t k = 0; k < count; ++k)
        for (int c = 0; c < v.components; ++c)
          buf[k * size_t(width) + size_t(c)] =
              v.base[nodes[k] * size_t(v.stride) + size_t(v.offset + c)];
      write_dataset(f, "grid_" + v.name, buf.data(), count, width, H5T_NATIVE_DOUBLE);
      fr.grid_attributes.push_back({v.name, width, "Float"});
    }
  }

  static std::string attribute_type(int width) {
    return width == 1 ? "Scalar" : width == 3 ? "Vector" : width == 6 ? "Tensor6" : "Matrix";
  }

  /// A Uniform grid of n points in `file`; with a time unless it is a piece of a spatial
  /// collection (which carries the time).
  static void polyvertex(std::ostream& x, const std::string& grid_name, const std::string& file,
                         const std::string& prefix, size_t n, const std::vector<Attribute>& attrs,
                         double time, bool piece = false) {
    x << "      <Grid Name=\"" << grid_name << "\" GridType=\"Uniform\">\n";
    if (!piece) x << "        <Time Value=\"" << time << "\"/>\n";
    x << "        <Topology TopologyType=\"Polyvertex\" NumberOfElements=\"" << n << "\"/>\n"
      << "        <Geometry GeometryType=\"XYZ\"><DataItem Dimensions=\"" << n
      << " 3\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">" << file << ":/" << prefix
      << "position</DataItem></Geometry>\n";
    for (const auto& a : attrs) {
      x << "        <Attribute Name=\"" << a.name << "\" AttributeType=\""
        << attribute_type(a.width) << "\" Center=\"Node\"><DataItem Dimensions=\"" << n;
      if (a.width > 1) x << " " << a.width;
      x << "\" NumberType=\"" << a.number_type << "\" Precision=\""
        << (a.number_type == "Int" ? 4 : 8) << "\" Format=\"HDF\">" << file << ":/" << prefix
        << a.name << "</DataItem></Attribute>\n";
    }
    x << "      </Grid>\n";
  }

  void write_index(const std::string& set, const std::vector<Frame>& frames, bool grid) {
    std::ostringstream x;
    x.precision(12);
    x << "<?xml version=\"1.0\" ?>\n<Xdmf Version=\"3.0\">\n  <Domain>\n"
      << "    <Grid Name=\"" << set << "\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
    for (const auto& fr : frames) {
      if (fr.pieces.empty()) {
        polyvertex(x, set, fr.file, "", fr.n, fr.attributes, fr.time);
        continue;
      }
      // One frame under mpirun: the ranks' pieces (a rank without particles has none).
      x << "      <Grid Name=\"" << set << "\" GridType=\"Collection\" "
        << "CollectionType=\"Spatial\">\n        <Time Value=\"" << fr.time << "\"/>\n";
      for (size_t r = 0; r < fr.pieces.size(); ++r)
        if (fr.pieces[r] > 0)
          polyvertex(x, set + rank_tag(int(r)), fr.file + rank_tag(int(r)) + ".h5", "",
                     size_t(fr.pieces[r]), fr.attributes, fr.time, true);
      x << "      </Grid>\n";
    }
    x << "    </Grid>\n";
    if (grid) {
      x << "    <Grid Name=\"grid\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
      for (const auto& fr : frames) {
        if (fr.grid_pieces.empty()) {
          polyvertex(x, "grid", fr.file, "grid_", fr.grid_nodes, fr.grid_attributes, fr.time);
          continue;
        }
        x << "      <Grid Name=\"grid\" GridType=\"Collection\" CollectionType=\"Spatial\">\n"
          << "        <Time Value=\"" << fr.time << "\"/>\n";
        for (size_t r = 0; r < fr.grid_pieces.size(); ++r)
          if (fr.grid_pieces[r] > 0)
            polyvertex(x, "grid" + rank_tag(int(r)), fr.file + rank_tag(int(r)) + ".h5", "grid_",
                       size_t(fr.grid_pieces[r]), fr.grid_attributes, fr.time, true);
        x << "      </Grid>\n";
      }
      x << "    </Grid>\n";
    }
    x << "  </Domain>\n</Xdmf>\n";
    write_file_atomically((std::filesystem::path(dir_) / (set + ".xdmf")).string(), x.str());
  }
};

LOAM_REGISTER_DEFAULT(Writer, Xdmf)

}  // namespace loam

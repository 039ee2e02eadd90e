#include "boundary.hpp"

#include <algorithm>
#include <cmath>

#include "diagnostics.hpp"
#include "params.hpp"

namespace loam {

const std::vector<std::string>& face_names() {
  static const std::vector<std::string> names{"x-", "x+", "y-", "y+", "z-", "z+"};
  return names;
}

Face parse_face(const std::string& name) {
  Face f;
  f.axis = name.empty() ? 0 : name[0] - 'x';
  f.upper = name.size() > 1 && name[1] == '+';
  return f;
}

bool check_face(const Face& f, int dim, const Params& p, const std::string& key, Diagnostics& d) {
  if (f.axis < dim) return true;
  d.error(p.where(key), p.path(key),
          "face '" + p.text(key) + "' does not exist in " + std::to_string(dim) + "D (faces: " +
              join(std::vector<std::string>(face_names().begin(), face_names().begin() + 2 * dim),
                   ", ") +
              ")");
  return false;
}

template <int D>
std::vector<size_t> face_nodes(const Grid<D>& grid, const Face& face) {
  std::vector<size_t> out;
  const int plane = face.upper ? grid.nodes[face.axis] - 1 : 0;
  for (size_t n = 0; n < grid.num_nodes; ++n)
    if (grid.node_ijk(n)[size_t(face.axis)] == plane) out.push_back(n);
  return out;
}

void add_phase_param(Schema& s) {
  s.choice("phase", {"both", "solid", "water"},
           "two-phase schemes: the phases this condition holds; both (the face is impermeable "
           "too), solid (the water passes: drained) or water")
      .def("both");
}

void add_reaction_name(Schema& s) {
  s.text("name",
         "name of this condition's reaction (the force it applies on the model) in history.csv "
         "(reaction_<name>_x, ...; two-phase schemes also reaction_<name>_water_x, ...) and "
         "summary.json; default <type>_<face>, or <type>_<position in the list> for a box");
}

int parse_phase_mask(const Params& p) {
  const std::string ph = p.text("phase");
  return ph == "solid" ? 1 : ph == "water" ? 2 : 3;
}

bool check_phase_mask(int mask, int scheme_phases, const Params& p, Diagnostics& d) {
  if (mask == 3 || scheme_phases > 1) return true;
  d.error(p.where("phase"), p.path("phase"),
          "phase: " + p.text("phase") +
              " needs a two-phase scheme (this scheme has one phase on the grid)");
  return false;
}

template <int D>
std::vector<double> face_node_areas(const Grid<D>& g, const Face& face,
                                    const std::vector<size_t>& nodes) {
  std::vector<double> area(nodes.size());
  for (size_t k = 0; k < nodes.size(); ++k) {
    const auto ijk = g.node_ijk(nodes[k]);
    double a = 1;
    for (int d = 0; d < D; ++d) {
      if (d == face.axis) continue;
      const bool edge = ijk[size_t(d)] == 0 || ijk[size_t(d)] == g.nodes[size_t(d)] - 1;
      a *= g.cell[size_t(d)] * (edge ? 0.5 : 1.0);
    }
    area[k] = a;
  }
  return area;
}

template std::vector<double> face_node_areas<1>(const Grid<1>&, const Face&,
                                                const std::vector<size_t>&);
template std::vector<double> face_node_areas<2>(const Grid<2>&, const Face&,
                                                const std::vector<size_t>&);
template std::vector<double> face_node_areas<3>(const Grid<3>&, const Face&,
                                                const std::vector<size_t>&);
void add_face_or_box_params(Schema& s, bool face_required_otherwise) {
  s.choice("face", face_names(), "grid face (or min and max: a box of nodes inside the grid)");
  s.vector("min", "m", "lower corner of a box whose nodes are held (instead of face)");
  s.vector("max", "m", "upper corner of a box whose nodes are held (instead of face)");
  s.check([face_required_otherwise](const Params& p, Diagnostics& d) {
    const bool box = p.has("min") || p.has("max");
    if ((face_required_otherwise && p.has("face") == box) || (p.has("face") && box) ||
        p.has("min") != p.has("max"))
      d.error(p.where(), p.path(), "give either face or both min and max (a box of nodes)");
    else if (box)  // a box of nodes may be flat (a sheet: one row of nodes), not inverted
      for (size_t k = 0; k < p.vec("min").size() && k < p.vec("max").size(); ++k)
        if (p.vec("max")[k] < p.vec("min")[k])
          d.error(p.where("max"), p.path("max"),
                  "max is below min along axis " + std::to_string(k) + ": an empty box");
  });
}

template <int D>
std::vector<size_t> box_nodes(const Grid<D>& g, const Params& p, Diagnostics& diag) {
  auto inside = [&](double x, int d) {
    const double tol = 1e-9 * g.cell[size_t(d)];
    return x >= p.vec("min")[size_t(d)] - tol && x <= p.vec("max")[size_t(d)] + tol;
  };
  // Whether the whole grid has a node in the box: per axis, the node rows nearest the box's
  // ends. Under mpirun a rank's stored box may hold none of its nodes; that is no error.
  for (int d = 0; d < D; ++d) {
    const double o = g.origin[size_t(d)], h = g.cell[size_t(d)];
    const int lo = std::clamp(int(std::ceil((p.vec("min")[size_t(d)] - o) / h - 1e-9)), 0,
                              g.nodes[size_t(d)] - 1);
    if (!inside(o + lo * h, d)) {
      diag.error(p.where("min"), p.path("min"),
                 "the box holds no grid node (a structure must span at least one node)");
      return {};
    }
  }
  std::vector<size_t> out;  // the stored nodes in the box
  for (size_t n = 0; n < g.num_nodes; ++n) {
    bool in = true;
    for (int d = 0; d < D; ++d) in = in && inside(g.node_coord(n, d), d);
    if (in) out.push_back(n);
  }
  return out;
}

template <int D>
void face_or_box_components(const Grid<D>& grid, const Params& p, const Face& face, bool box,
                            std::vector<size_t>& nodes, std::vector<int>& components,
                            Diagnostics& d) {
  if (box)
    nodes = box_nodes(grid, p, d);
  else if (!check_face(face, D, p, "face", d))
    return;
  else
    nodes = face_nodes(grid, face);
  if (!p.has("directions")) {
    components.push_back(face.axis);
    return;
  }
  for (const auto& c : p.strings("directions")) {
    const int axis = c.size() == 1 ? c[0] - 'x' : -1;
    if (axis < 0 || axis >= D)
      d.error(p.where("directions"), p.path("directions"),
              "unknown direction '" + c + "' (use x" + (D > 1 ? ", y" : "") + (D > 2 ? ", z" : "") +
                  ")");
    else
      components.push_back(axis);
  }
}

#define LOAM_FACE_OR_BOX(D)                                                                 \
  template void face_or_box_components<D>(const Grid<D>&, const Params&, const Face&, bool, \
                                          std::vector<size_t>&, std::vector<int>&, Diagnostics&);
LOAM_FACE_OR_BOX(1)
LOAM_FACE_OR_BOX(2)
LOAM_FACE_OR_BOX(3)
#undef LOAM_FACE_OR_BOX

template std::vector<size_t> box_nodes<1>(const Grid<1>&, const Params&, Diagnostics&);
template std::vector<size_t> box_nodes<2>(const Grid<2>&, const Params&, Diagnostics&);
template std::vector<size_t> box_nodes<3>(const Grid<3>&, const Params&, Diagnostics&);
template std::vector<size_t> face_nodes<1>(const Grid<1>&, const Face&);
template std::vector<size_t> face_nodes<2>(const Grid<2>&, const Face&);
template std::vector<size_t> face_nodes<3>(const Grid<3>&, const Face&);

}  // namespace loam

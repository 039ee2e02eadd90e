#include "boundary.hpp"

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

template std::vector<size_t> face_nodes<1>(const Grid<1>&, const Face&);
template std::vector<size_t> face_nodes<2>(const Grid<2>&, const Face&);
template std::vector<size_t> face_nodes<3>(const Grid<3>&, const Face&);

}  // namespace loam

#pragma once
// Contact plugin interface: the law by which two bodies that meet at a grid node exchange
// momentum. Each body in contact has its own velocity field on the grid (Bardenhagen et al.
// 2000, "The material-point method for granular materials"; Bardenhagen et al. 2001, "An
// improved contact algorithm for the material point method and application to stress
// propagation in granular material"); framework/contact_fields.hpp builds the fields and calls
// the law at every node where two of them have mass. A law sees one pair of fields at one node:
// their masses, their velocities after the grid update, and the unit normal from the first body
// towards the second. It must conserve the pair's momentum m_a v_a + m_b v_b.
#include <string>
#include <vector>

#include "params.hpp"

namespace loam {

/// Whether a contact law judges the approach of two fields itself or is told they approach.
enum class Approach { kJudged, kFound };

template <int D>
class Contact {
 public:
  static constexpr const char* kind = "contact";
  virtual ~Contact() = default;
  /// Correct the velocities va, vb of two fields of masses ma, mb (both > 0) that meet at a
  /// node; n is the unit normal pointing from body a towards body b. mb is +infinity where b is
  /// a rigid body (framework/rigid_motion.hpp): vb must then stay as it is. `approach`: whether the
  /// law judges from va, vb if the bodies approach (the grid update), or they were found
  /// approaching at this node in the step's update (the MUSL re-map: the law then acts as if
  /// they were, so that the strain follows the motion the update gave).
  virtual void exchange(double ma, double mb, double (&va)[D], double (&vb)[D],
                        const double (&n)[D], Approach approach) const = 0;
  /// The bodies in contact with each other (empty: every body).
  const std::vector<std::string>& bodies() const { return bodies_; }

 protected:
  explicit Contact(const Params& p) : bodies_(p.strings("bodies")) {}

 private:
  std::vector<std::string> bodies_;
};

/// The parameters every contact law takes: which bodies are in contact.
inline void add_contact_bodies_param(Schema& s) {
  s.string_list("bodies",
                "the bodies that touch each other, each on its own velocity field (every pair of "
                "them is in contact; the others move with the field they share); empty: every "
                "body")
      .def("[]");
}

}  // namespace loam

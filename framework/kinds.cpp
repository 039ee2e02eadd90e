// The plugin kinds the core knows (never the plugins themselves), in `loam plugins` order.
#include "registry.hpp"

LOAM_REGISTER_KIND("shape_function", "interpolation between particles and grid nodes")
LOAM_REGISTER_KIND("scheme", "what one explicit step does (mixture formulation, update order)")
LOAM_REGISTER_KIND("material", "constitutive model; stress tension positive (Pa)")
LOAM_REGISTER_KIND("drag",
                   "interaction force between pore water and soil skeleton (two-phase schemes)")
LOAM_REGISTER_KIND("boundary", "constraints on grid-face nodes")
LOAM_REGISTER_KIND("load", "external forces on particles or nodes")
LOAM_REGISTER_KIND("time_function",
                   "a factor f(t) of the time since its stage began (a load's ramp or pulse)")
LOAM_REGISTER_KIND("damping", "numerical damping of nodal forces")
LOAM_REGISTER_KIND("contact",
                   "how bodies on their own velocity fields exchange momentum where they meet")
LOAM_REGISTER_KIND("source", "particles created while the run goes (inflow)")
LOAM_REGISTER_KIND("sink", "particles removed while the run goes (outflow)")
LOAM_REGISTER_KIND("generator", "regions filled with particles")
LOAM_REGISTER_KIND("field", "spatial fields for initial conditions (a list is a constant)")
LOAM_REGISTER_KIND("reference", "analytic references for `verify:`, with error metrics")
LOAM_REGISTER_KIND("writer", "output formats")

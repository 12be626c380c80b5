#include "partita/adapters/register_all.hpp"

#ifdef PARTITA_HAVE_DEM
#include "dem/dem_adapter.hpp"
#endif
#ifdef PARTITA_HAVE_FEM
#include "fem/fem_adapter.hpp"
#endif
#ifdef PARTITA_HAVE_TUBE1D
#include "tube1d/tube_fluid_adapter.hpp"
#include "tube1d/tube_solid_adapter.hpp"
#endif

namespace partita::adapters {

void register_all(coupling::Registries& r) {
#ifdef PARTITA_HAVE_DEM
  r.solvers.add(
      "dem", "native DEM: Hertz-Mindlin spheres, walls, STL meshes as coupling interfaces",
      DemAdapter::create, DemAdapter::spec(), DemAdapter::monitor_table().docs());
#endif
#ifdef PARTITA_HAVE_FEM
  r.solvers.add(
      "fem",
      "native FEM: Hex8/Hex20/Tet4/Tet10; linear elastic, Neo-Hooke or J2 plasticity; static, "
      "Newmark or central-difference transient",
      FemAdapter::create, FemAdapter::spec(), FemAdapter::monitor_table().docs());
#endif
#ifdef PARTITA_HAVE_TUBE1D
  r.solvers.add("tube1d-fluid",
                "1D elastic tube: quasi-1D incompressible flow (writes pressure, reads area)",
                TubeFluidAdapter::create, TubeFluidAdapter::spec(),
                TubeFluidAdapter::monitor_table().docs());
  r.solvers.add("tube1d-solid",
                "1D elastic tube: tube law a(p) (reads pressure, writes cross_section_area)",
                TubeSolidAdapter::create, TubeSolidAdapter::spec(),
                TubeSolidAdapter::monitor_table().docs());
#endif
  (void)r;
}

}  // namespace partita::adapters

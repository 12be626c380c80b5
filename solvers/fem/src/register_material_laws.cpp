#include "partita/fem/decoupled_neo_hooke_law.hpp"
#include "partita/fem/finite_strain_j2_law.hpp"
#include "partita/fem/j2_plasticity_law.hpp"
#include "partita/fem/linear_elastic_law.hpp"
#include "partita/fem/material_law_registry.hpp"
#include "partita/fem/neo_hooke_law.hpp"

namespace partita::fem {

// The built-in laws, one line each; a new law adds its entry here (and a plugin its own through
// the program that loads it). The first is the default of a case that names none.
void register_material_laws(MaterialLawRegistry& registry) {
  registry.add(linear_elastic_law_entry());
  registry.add(neo_hooke_law_entry());
  registry.add(decoupled_neo_hooke_law_entry());
  registry.add(j2_plasticity_law_entry());
  registry.add(finite_strain_j2_law_entry());
}

}  // namespace partita::fem

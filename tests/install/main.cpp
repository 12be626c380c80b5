#include <iostream>
#include "partita/adapters/register_all.hpp"
#include "partita/coupling/registries.hpp"
#include "partita/run/case_run.hpp"
int main() {
  partita::coupling::Registries r;
  partita::coupling::register_builtin(r);
  partita::adapters::register_all(r);
  std::cout << r.solvers.names().size() << " solvers, " << r.mappers.names().size() << " mappers"
            << (partita::run::case_spec(r) ? ", a case schema" : "") << "\n";
}

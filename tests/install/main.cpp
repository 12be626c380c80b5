#include <iostream>
#include "partita/adapters/register_all.hpp"
#include "partita/coupling/registries.hpp"
int main() {
  partita::coupling::Registries r;
  partita::coupling::register_builtin(r);
  partita::adapters::register_all(r);
  std::cout << r.solvers.names().size() << " solvers, " << r.mappers.names().size() << " mappers\n";
}

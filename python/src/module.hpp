#pragma once
// The `partita._partita` extension module (pybind11): the run library's front end for Python,
// beside the `partita` executable. Two translation units (pybind11 compiles slowly): module.cpp
// (the module, the version, errors, check) and run.cpp (run and sweep, on a worker thread while
// the caller's thread keeps Python's signals and the progress callback).

#include <memory>
#include <string>
#include <vector>

#include <pybind11/pybind11.h>

#include "partita/interface/error.hpp"
#include "partita/interface/solver.hpp"

#include "partita/coupling/registries.hpp"

namespace partita::python {

/// The registries of the stock `partita` executable: the core's and every in-tree adapter's.
const coupling::Registries& stock_registries();

/// python_solver.cpp: the registries the module's calls use: the stock ones and the solvers registered
/// from Python (partita.register_solver). Call it with the GIL held; a call keeps its snapshot
/// for its whole run (a solver registered meanwhile counts from the next call).
std::shared_ptr<const coupling::Registries> registries();

/// python_solver.cpp: a case whose participant names a solver registered in Python is refused by a
/// sweep (its variants are partita processes, which do not know it).
void refuse_python_solvers(const std::string& case_file, const std::vector<std::string>& overrides);

/// python_solver.cpp: a partita.Mesh (or any object with its attributes: name, points, triangles,
/// weights, reads, writes, prescribed) as an InterfaceMesh; errors name `who`.
InterfaceMesh to_interface_mesh(pybind11::handle mesh, const std::string& who);

/// python_solver.cpp: _partita.add_solver, python_solver_names and quantity.
void bind_solver(pybind11::module_& m);

/// Where each "key=value" override comes from, for messages: "partita.run(set={'key': ...})".
std::vector<SourceLocation> override_origins(const std::vector<std::string>& overrides,
                                             const std::string& call);

/// A case with a `plugins:` list is refused with a clear error (the module loads no plugins).
void refuse_plugins(const std::string& case_file, const std::vector<std::string>& overrides);

/// external.cpp (built where partita has MPI, PARTITA_PYTHON_MPI): _partita.ExternalParticipant,
/// partita::mpi::ExternalParticipant for a Python program under mpirun.
void bind_external(pybind11::module_& m);

/// run.cpp: _partita.run and _partita.sweep.
void bind_run(pybind11::module_& m);

}  // namespace partita::python

#include "partita/coupling/registries.hpp"

#include "partita/coupling/acceleration/aitken.hpp"
#include "partita/coupling/acceleration/constant_relaxation.hpp"
#include "partita/coupling/acceleration/iqn_imvj.hpp"
#include "partita/coupling/acceleration/iqn_ils.hpp"
#include "partita/coupling/convergence/absolute_convergence.hpp"
#include "partita/coupling/convergence/relative_convergence.hpp"
#include "partita/coupling/convergence/residual_relative_convergence.hpp"
#include "partita/coupling/explicit_scheme.hpp"
#include "partita/coupling/implicit_scheme.hpp"
#include "partita/coupling/mapping/register_mappers.hpp"

namespace partita::coupling {

namespace {
std::shared_ptr<const config::Spec> scheme_spec(const std::string& name, const std::string& doc,
                                                bool implicit) {
  auto s = std::make_shared<config::Spec>(name, doc);
  if (implicit) {
    s->list("convergence", "convergence measures (all must hold)", nullptr).required();
    s->any("acceleration",
           "acceleration of the fixed-point iteration: a name, or {type: name, <its own keys>} "
           "(partita docs NAME lists them)");
    s->integer("max_iterations", "most iterations per window").min(1).def(100);
    s->choice("on_max_iterations", "what happens at max_iterations", {"error", "accept"})
        .def("accept");
  }
  return s;
}
}  // namespace

void register_builtin(Registries& r) {
  register_mappers(r.mappers);

  r.schemes.add("explicit-serial",
                "participants in order, each once per window; later ones see this window's data",
                ExplicitScheme::create_serial,
                scheme_spec("explicit-serial", "staggered, first order", false));
  r.schemes.add("explicit-parallel",
                "all participants once per window from the previous window's data",
                ExplicitScheme::create_parallel,
                scheme_spec("explicit-parallel", "Jacobi-like, first order", false));
  r.schemes.add("implicit-serial",
                "serial order, windows repeated from checkpoints until converged",
                ImplicitScheme::create_serial,
                scheme_spec("implicit-serial", "Gauss-Seidel fixed point", true));
  r.schemes.add("implicit-parallel",
                "all participants from the same iterate, repeated until converged",
                ImplicitScheme::create_parallel,
                scheme_spec("implicit-parallel", "Jacobi fixed point", true));

  r.accelerations.add("constant", "constant under-relaxation x + omega (H(x) - x)",
                      ConstantRelaxation::create, ConstantRelaxation::spec());
  r.accelerations.add("aitken", "Aitken's dynamic under-relaxation", Aitken::create,
                      Aitken::spec());
  r.accelerations.add("iqn-ils",
                      "interface quasi-Newton, least-squares inverse Jacobian, QR filter",
                      IqnIls::create, IqnIls::spec());
  r.accelerations.add("iqn-imvj",
                      "interface quasi-Newton, multi-vector inverse Jacobian kept across windows",
                      IqnImvj::create, IqnImvj::spec());

  r.convergence_measures.add("absolute", "|x^k - x^(k-1)| <= limit (data unit)",
                             AbsoluteConvergence::create,
                             convergence_spec("absolute", "absolute change between iterations"));
  r.convergence_measures.add("relative", "|x^k - x^(k-1)| <= limit |x^k|",
                             RelativeConvergence::create,
                             convergence_spec("relative", "change relative to the new values"));
  r.convergence_measures.add(
      "residual-relative", "|x^k - x^(k-1)| <= limit |x^1 - x^0|",
      ResidualRelativeConvergence::create,
      convergence_spec("residual-relative", "residual relative to the window's first"));
}

}  // namespace partita::coupling

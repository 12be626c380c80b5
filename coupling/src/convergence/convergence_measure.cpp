#include "partita/coupling/convergence/convergence_measure.hpp"

namespace partita::coupling {

std::shared_ptr<config::Spec> convergence_spec(const std::string& name, const std::string& doc) {
  auto s = std::make_shared<config::Spec>(name, doc);
  s->string("type", "the measure's name").required();
  s->string("data", "the exchanged data field it measures (all exchanges of that name)").required();
  s->real("limit", "the measure holds when its value is at most this").positive().required();
  return s;
}

}  // namespace partita::coupling

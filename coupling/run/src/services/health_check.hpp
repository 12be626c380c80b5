#pragma once
// The divergence stop: after each window, every exchanged field is checked for non-finite values
// and each participant's solver for its own finding (Participant::check_state); either stops the
// run with a diagnosis (partita::Error). The exchanges whose balance-audit totals of the window
// were finite are not read again: a finite total has only finite terms.

#include <vector>

#include "balance_audit.hpp"
#include "partita/coupling/exchange.hpp"
#include "partita/coupling/participant.hpp"
#include "partita/run/service.hpp"

namespace partita::run {

class HealthCheck final : public Service {
 public:
  HealthCheck(std::vector<const coupling::Exchange*> exchanges,
              std::vector<coupling::Participant*> participants, const BalanceAudit& audit)
      : exchanges_(std::move(exchanges)), participants_(std::move(participants)), audit_(audit) {}

  void observe(coupling::FinishedWindow& w) override;

 private:
  std::vector<const coupling::Exchange*> exchanges_;
  std::vector<coupling::Participant*> participants_;
  const BalanceAudit& audit_;
};

}  // namespace partita::run

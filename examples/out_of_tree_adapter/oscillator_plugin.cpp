// The oscillator as a plugin for the stock partita executable (B: the example's build folder):
//   partita run B/oscillator_plugin.yaml                  (the case lists the library: plugins:)
//   partita run oscillator.yaml --plugin B/liboscillator_plugin.so
//   partita run lid_on_granules.yaml --plugin B/liboscillator_plugin.so   (coupled with the DEM)
//   partita list --plugin B/liboscillator_plugin.so        (and check, docs, --set, sweeps,
//   --resume)
// PARTITA_PLUGIN defines the library's entry point and records the partita version it is built
// against (partita/coupling/plugin.hpp); the body adds the solver to the registries given.
#include "oscillator_adapter.hpp"
#include "partita/coupling/plugin.hpp"

PARTITA_PLUGIN(registries) {
  OscillatorAdapter::register_in(registries.solvers);
}

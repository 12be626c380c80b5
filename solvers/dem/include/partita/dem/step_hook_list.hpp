#pragma once
// The step hooks of a System, owned; copying the list clones every hook (a copied System gets its
// own breakage counters and random-number state).

#include "partita/dem/step_hook.hpp"

#include <memory>
#include <vector>

namespace partita::dem {

class StepHookList {
 public:
  StepHookList() = default;
  StepHookList(const StepHookList& other) {
    for (const auto& h : other.hooks_) hooks_.push_back(h->clone());
  }
  StepHookList& operator=(const StepHookList& other) {
    if (this != &other) {
      hooks_.clear();
      for (const auto& h : other.hooks_) hooks_.push_back(h->clone());
    }
    return *this;
  }
  StepHookList(StepHookList&&) noexcept = default;
  StepHookList& operator=(StepHookList&&) noexcept = default;

  int add(std::unique_ptr<StepHook> hook) {
    hooks_.push_back(std::move(hook));
    return static_cast<int>(hooks_.size()) - 1;
  }
  int size() const { return static_cast<int>(hooks_.size()); }
  bool empty() const { return hooks_.empty(); }
  StepHook& operator[](int k) { return *hooks_[k]; }
  const StepHook& operator[](int k) const { return *hooks_[k]; }

 private:
  std::vector<std::unique_ptr<StepHook>> hooks_;
};

}  // namespace partita::dem

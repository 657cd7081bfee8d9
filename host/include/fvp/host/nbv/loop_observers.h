// Several observers of one next-best-view loop (the loop takes one): a trial's log and an
// automatic stop both listen to every view.
#pragma once

#include <string>
#include <vector>

#include "fvp/host/nbv/nbv_loop.h"

namespace fvp::host::nbv {

/// Passes every event to each observer added, in the order they were added.
class LoopObservers : public LoopObserver {
 public:
  /// observer must outlive this; null is ignored.
  void add(LoopObserver* observer) {
    if (observer) observers_.push_back(observer);
  }
  void onView(const ViewEvent& event) override {
    for (LoopObserver* o : observers_) o->onView(event);
  }
  void onPlan(const PlanEvent& event) override {
    for (LoopObserver* o : observers_) o->onPlan(event);
  }
  void onDroppedFrame(const std::string& detail) override {
    for (LoopObserver* o : observers_) o->onDroppedFrame(detail);
  }

 private:
  std::vector<LoopObserver*> observers_;
};

}  // namespace fvp::host::nbv

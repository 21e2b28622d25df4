#pragma once

#include <diagnostic_updater/diagnostic_updater.h>

#include <string>

#include "work_queue.h"

namespace sift_hull {

/// A work queue's counts in a node's diagnostics (/diagnostics): OK while nothing was dropped,
/// WARN once the input has outrun the processing.
inline void reportQueue(const WorkCounts& counts, const std::string& items,
                        diagnostic_updater::DiagnosticStatusWrapper* status) {
  status->add(items + " received", counts.pushed);
  status->add(items + " processed", counts.done);
  status->add(items + " dropped", counts.dropped);
  status->add(items + " waiting", counts.waiting);
  if (counts.dropped > 0) {
    status->summaryf(diagnostic_msgs::DiagnosticStatus::WARN,
                     "%llu %s dropped: the input comes faster than they are processed",
                     static_cast<unsigned long long>(counts.dropped), items.c_str());
  } else {
    status->summary(diagnostic_msgs::DiagnosticStatus::OK, "keeping up");
  }
}

}  // namespace sift_hull

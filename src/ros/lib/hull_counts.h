#pragma once

#include <diagnostic_updater/DiagnosticStatusWrapper.h>

#include <atomic>
#include <cstdint>
#include <utility>

namespace sift_hull {

/// What came into the hull node and what became of it, since the start, for /diagnostics. Each
/// silhouette received is unpaired (or waiting to pair), waiting for its pose or dropped without
/// one, queued or dropped from the full queue, or made a view that is carved, waiting for a box,
/// redundant, skipped, refused, bad, or discarded by ~reset. Each surface_points message is
/// waiting, without pose, dropped from the full queue, bad, refused, left empty, merged, or
/// discarded by ~reset. Written by the node's threads, read by the diagnostics.
struct HullCounts {
  std::atomic<uint64_t> silhouettes{0}, paired{0}, carved{0}, redundant{0}, skipped{0},
      refused{0}, bad{0}, reset{0};
  std::atomic<uint64_t> pairs{0}, pairs_merged{0}, pairs_bad{0}, pairs_refused{0},
      pairs_empty{0}, pairs_queue_full{0}, pairs_no_pose{0}, pairs_reset{0};
  std::atomic<uint64_t> points_subsampled{0}, points_outside{0};
  std::atomic<uint64_t> waiting{0}, free_voxels{0};  ///< now

  /// Adds them to `status`, with the views dropped without a pose (PoseWait's count).
  void report(uint64_t views_without_pose,
              diagnostic_updater::DiagnosticStatusWrapper* status) const {
    const std::pair<const char*, uint64_t> rows[] = {
        {"silhouettes received", silhouettes},
        {"views unpaired", silhouettes - paired},
        {"views without pose", views_without_pose},
        {"views carved", carved},
        {"views waiting for a box", waiting},
        {"views redundant", redundant},
        {"views skipped", skipped},
        {"views refused", refused},
        {"views bad", bad},
        {"views discarded by ~reset", reset},
        {"surface_points received", pairs},
        {"surface_points merged", pairs_merged},
        {"surface_points without pose", pairs_no_pose},
        {"surface_points dropped (queue full)", pairs_queue_full},
        {"surface_points bad", pairs_bad},
        {"surface_points refused (far camera)", pairs_refused},
        {"surface_points with no point kept", pairs_empty},
        {"surface_points discarded by ~reset", pairs_reset},
        {"surface points subsampled away", points_subsampled},
        {"surface points outside the margin", points_outside},
        {"free voxels", free_voxels},
    };
    for (const auto& [label, value] : rows) status->add(label, value);
  }
};

}  // namespace sift_hull

#pragma once
// Private to Interaction: the viewer's live fit. The segmentation runs on a
// worker thread (evolveInRegion); the interface thread starts, pauses and
// stops it, moves the pull it shares with it, and takes the surfaces it
// publishes about 25 times a second. No VTK here.
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "dynsub/Landmarks.h"
#include "dynsub/PullForce.h"
#include "dynsub/Segmentation.h"
#include "dynsub/Tessellation.h"

namespace dynsub {

// How often a running fit publishes its surface.
constexpr auto kRedrawInterval = std::chrono::milliseconds(40);

class FitWorker {
 public:
  // `image` must outlive the worker.
  FitWorker(const Volume& image, const SegmentOptions& options, double initialFraction, double pullStiffness);
  ~FitWorker();
  FitWorker(const FitWorker&) = delete;
  FitWorker& operator=(const FitWorker&) = delete;

  // A new fit of `landmarks` (at least 4), after cancelling any running one
  // (the pull stays held and acts from the first step): from the last
  // finished fit (its mesh and level) if there is one, reusing its region
  // while the landmarks and the surface stay inside; otherwise from the cube
  // inside the landmarks.
  void start(const std::vector<Landmark>& landmarks);
  // Cancels a running fit, waits for it, and lets go of the pull.
  void stop();
  // stop(), and forget the last fit, its region, the status and any surface not taken.
  void forget();
  void togglePause();

  bool running() const { return running_; }
  // Whether a finished fit is there to refit from (a running fit may be
  // writing it: read under the lock).
  bool hasFit() const;
  // The fit's state for the status line ("fitting: level 1, step 40, ..."),
  // empty before the first fit.
  std::string status() const;

  // The pull: the surface point held at `anchor`, drawn to `target`; `grab`:
  // it takes hold anew. A running fit takes it, decided under the lock the
  // end of a fit takes, so the fit cannot end between the test and the move:
  // true. Without a running fit nothing changes: false.
  bool pullRunningFit(const Vector3& anchor, const Vector3& target, bool grab);
  // Takes hold before start() (a refit that settled at once would never see a later one).
  void grab(const Vector3& anchor, const Vector3& target) { pull_.grab(anchor, target); }
  void release() { pull_.release(); }

  // The surface published since the last call, if any.
  std::optional<TriangleSurface> take();

 private:
  struct Fitted {
    ControlMesh mesh;
    LevelOrigin origin;
  };
  void cancelAndJoin();
  void run(const std::vector<Landmark>& landmarks, const std::optional<Fitted>& start);
  void publish(TriangleSurface surface, const std::string& text);

  const Volume& image_;
  SegmentOptions options_;
  double initialFraction_;
  PullForceModel pull_;
  std::thread worker_;
  std::atomic<bool> running_{false};
  mutable std::mutex mutex_;
  std::condition_variable resume_;
  bool paused_ = false, cancel_ = false;
  bool fresh_ = false;  // a surface is waiting in published_
  TriangleSurface published_;
  std::string text_;
  // Written by the worker under the lock; start() reads it once the last
  // worker has ended.
  std::optional<Fitted> fitted_;
  // The worker's alone while one runs.
  std::unique_ptr<const SegmentationRegion> region_;
};

}  // namespace dynsub

#include "FitWorker.h"

#include <iomanip>
#include <sstream>

#include "dynsub/LimitSurface.h"

namespace dynsub {
namespace {

struct FitCancelled {};

}  // namespace

FitWorker::FitWorker(const Volume& image, const SegmentOptions& options, double initialFraction, double pullStiffness)
    : image_(image), options_(options), initialFraction_(initialFraction), pull_(pullStiffness) {}

FitWorker::~FitWorker() { stop(); }

void FitWorker::start(const std::vector<Landmark>& landmarks) {
  cancelAndJoin();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    cancel_ = false;
    paused_ = false;
    text_ = "fitting: starting";
  }
  running_ = true;
  worker_ = std::thread([this, marks = landmarks, start = fitted_] { run(marks, start); });
}

void FitWorker::cancelAndJoin() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    cancel_ = true;
    paused_ = false;
  }
  resume_.notify_all();
  if (worker_.joinable()) worker_.join();
}

void FitWorker::stop() {
  cancelAndJoin();
  pull_.release();
}

void FitWorker::forget() {
  stop();
  region_.reset();
  std::lock_guard<std::mutex> lock(mutex_);
  fitted_.reset();
  text_.clear();
  fresh_ = false;
}

void FitWorker::togglePause() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    paused_ = !paused_;
  }
  resume_.notify_all();
}

bool FitWorker::hasFit() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return fitted_.has_value();
}

std::string FitWorker::status() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return text_ + (paused_ && running_ ? " (paused)" : "");
}

bool FitWorker::pullRunningFit(const Vector3& anchor, const Vector3& target, bool grab) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!running_) return false;
  if (grab) {
    pull_.grab(anchor, target);
  } else {
    pull_.moveTo(target);
  }
  return true;
}

std::optional<TriangleSurface> FitWorker::take() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!fresh_) return std::nullopt;
  fresh_ = false;
  return std::move(published_);
}

void FitWorker::publish(TriangleSurface surface, const std::string& text) {
  std::lock_guard<std::mutex> lock(mutex_);
  published_ = std::move(surface);
  fresh_ = true;
  text_ = text;
}

// The worker thread: the segmentation pipeline with a live observer.
void FitWorker::run(const std::vector<Landmark>& marks, const std::optional<Fitted>& start) {
  try {
    const auto started = std::chrono::steady_clock::now();
    const ControlMesh initial = start ? start->mesh : initialFromLandmarks(marks, initialFraction_);
    if (!start || !region_ || !region_->covers(landmarkPositions(marks)) || !region_->covers(initial.points()))
      region_ = std::make_unique<const SegmentationRegion>(image_, marks, initial, options_);
    auto last = std::chrono::steady_clock::now() - kRedrawInterval;
    auto observe = [&](const Progress& p) {
      {
        std::unique_lock<std::mutex> lock(mutex_);
        resume_.wait(lock, [&] { return !paused_ || cancel_; });
        if (cancel_) throw FitCancelled{};
      }
      const auto now = std::chrono::steady_clock::now();
      if (now - last < kRedrawInterval || !p.surface || !p.controlPoints) return;
      last = now;
      std::ostringstream text;
      text << (start ? "refitting" : "fitting") << ": level " << p.level << ", step " << p.step << std::scientific
           << std::setprecision(3) << ", energy " << p.energy << " N mm";
      publish(tessellate(*p.surface, *p.controlPoints, 4), text.str());
    };
    unsigned moves = pull_.moves();
    SegmentResult result = evolveInRegion(*region_, marks, initial, start ? start->origin : LevelOrigin{}, options_,
                                          observe, {&pull_});
    for (;;) {
      {
        std::lock_guard<std::mutex> lock(mutex_);
        fitted_ = Fitted{result.mesh, result.origin};
      }
      const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
      double worst = 0;
      for (double d : result.landmarkDistances) worst = std::max(worst, d);
      std::ostringstream text;
      text << (start ? "refit" : "fit") << " done: " << result.mesh.vertexCount() << " control vertices, "
           << result.levels.back().level << " refinement(s), " << result.steps << " steps in " << std::fixed
           << std::setprecision(2) << seconds << " s;\nfarthest landmark " << worst << " mm";
      const LimitSurface limit(result.mesh);
      publish(tessellate(limit, result.mesh.points(), outputSegments(limit)), text.str());
      {
        // The pull moved during the fit, perhaps after its last step (a fit
        // may settle on a step that read the new target before moving to
        // it, or the hand moved while this one was being published): go on
        // from where it settled until a fit has seen the pull stand still.
        // Decided under the lock pullRunningFit takes, so no move falls
        // between this test and the end of the fit.
        std::lock_guard<std::mutex> lock(mutex_);
        if (!pull_.active() || pull_.moves() == moves) {
          running_ = false;
          return;
        }
        moves = pull_.moves();
      }
      result = evolveInRegion(*region_, marks, result.mesh, result.origin, options_, observe, {&pull_});
    }
  } catch (const FitCancelled&) {
    std::lock_guard<std::mutex> lock(mutex_);
    text_ = "fitting stopped";
  } catch (const std::exception& e) {
    std::lock_guard<std::mutex> lock(mutex_);
    text_ = std::string("fitting failed: ") + e.what();
  }
  running_ = false;
}

}  // namespace dynsub

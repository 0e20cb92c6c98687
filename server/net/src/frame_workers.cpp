#include "frame_workers.h"

#include <algorithm>
#include <cstdio>

#include "haarcast/core/check.h"
#include "haarcast/net/encode.h"
#include "haarcast/net/left_behind.h"

namespace haarcast::net {
namespace {

using Clock = FrameWorkers::Clock;
using namespace std::chrono_literals;

double secondsSince(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// "30", "0.3": as an operator wrote the deadline.
std::string formatSeconds(double seconds) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", seconds);
  return text;
}

bool isCancelled(const RenderJob& job) { return job.cancelled && job.cancelled(); }

}  // namespace

FrameWorkers::FrameWorkers(const RenderService::Options& options, Metrics& metrics)
    : options_(options), metrics_(metrics) {}

FrameWorkers::~FrameWorkers() = default;

void FrameWorkers::start() {
  {
    std::lock_guard lock(mutex_);
    for (int i = 0; i < options_.workers; ++i) spawnLocked();
  }
  if (options_.frameDeadlineSeconds > 0.0) watchdog_ = std::thread([self = shared_from_this()] { self->watch(); });
  encoders_.start(options_.encoders);
}

// A render thread; it holds this object (and its Worker) for as long as it
// runs, which may be for ever. Under mutex_.
void FrameWorkers::spawnLocked() {
  auto w = std::make_shared<Worker>();
  workers_.push_back(w);
  w->thread = std::thread([self = shared_from_this(), w] { self->workerLoop(w); });
}

void FrameWorkers::log(const std::string& line) const {
  if (options_.log) options_.log(line);
}

void FrameWorkers::submit(RenderJob job) {
  const render::Renderer& renderer = *job.renderer->renderer;
  std::pair<std::string, std::string> key{renderer.backend(), renderer.deviceName()};
  {
    std::lock_guard lock(mutex_);
    if (stopping_) return;
    auto [it, fresh] = devices_.try_emplace(key);
    Device& device = it->second;
    if (fresh) {
      device.backend = key.first;
      device.name = key.second;
    }
    if (device.stuck == 0) {
      queue_.push_back({std::move(job), Clock::now(), &device});
    } else {
      // Fails at once on an encode thread (a service thread), rather than
      // waiting for a worker behind other sessions' frames.
      encoders_.push([job = std::move(job), error = unhealthyError(device)] { job.done(std::nullopt, error); });
      return;
    }
  }
  queueCv_.notify_all();
}

std::string FrameWorkers::unhealthyError(const Device& d) {
  return "device " + d.name + " (" + d.backend + ") is unhealthy: " + d.reason +
         " and has not returned; its frames fail until it does or the server restarts";
}

// The next job a worker may start, or none; `dropped` takes the jobs found
// cancelled, `failed` those of an unhealthy device. A job whose device is
// busy is passed over (it holds no worker while it waits); none passes one
// waiting for the budget, so a large frame is not starved by small ones.
std::optional<FrameWorkers::Queued> FrameWorkers::pickLocked(std::vector<RenderJob>& dropped, std::vector<Failed>& failed) {
  budgetWait_ = false;
  for (auto it = queue_.begin(); it != queue_.end();) {
    if (isCancelled(it->job)) {
      dropped.push_back(std::move(it->job));
      it = queue_.erase(it);
      continue;
    }
    const Device& device = *it->device;
    if (device.stuck > 0) {  // it turned unhealthy while this job waited
      failed.emplace_back(std::move(it->job), unhealthyError(device));
      it = queue_.erase(it);
      continue;
    }
    const render::Renderer& renderer = *it->job.renderer->renderer;
    const std::size_t slots = renderer.framesInFlight();
    if ((slots == 1 && device.busy) || (slots > 1 && slotsInUse(renderer) >= slots)) {
      ++it;
      continue;
    }
    const std::size_t p = chargeOf(it->job);
    if (options_.serverPixelBudget && pixelsInFlight_ > 0 && pixelsInFlight_ + p > options_.serverPixelBudget) {
      budgetWait_ = true;  // and nobody passes it
      return std::nullopt;
    }
    Queued next = std::move(*it);
    queue_.erase(it);
    return next;
  }
  return std::nullopt;
}

std::size_t FrameWorkers::slotsInUse(const render::Renderer& renderer) const {
  const auto it = rendering_.find(&renderer);
  return it == rendering_.end() ? 0 : it->second;
}

// What a job holds of the budget from its start: its declared pixels (a
// job over the session limit fails before rendering and holds nothing).
std::size_t FrameWorkers::chargeOf(const RenderJob& job) const {
  return job.pixels > options_.maxSessionPixels ? 0 : job.pixels;
}

void FrameWorkers::workerLoop(const std::shared_ptr<Worker>& w) {
  for (;;) {
    std::optional<Queued> next;
    std::vector<RenderJob> dropped;
    std::vector<Failed> failed;
    {
      std::unique_lock lock(mutex_);
      for (;;) {
        if (stopping_ || w->abandoned) {
          w->exited = true;
          exitCv_.notify_all();
          return;
        }
        next = pickLocked(dropped, failed);
        if (next || !dropped.empty() || !failed.empty()) break;
        queueCv_.wait(lock);
      }
      if (next) {
        w->device = next->device;
        const render::Renderer& renderer = *next->job.renderer->renderer;
        w->holdsDevice = renderer.framesInFlight() == 1;
        if (w->holdsDevice) w->device->busy = true;
        w->slotOf = renderer.framesInFlight() > 1 ? &renderer : nullptr;
        if (w->slotOf) ++rendering_[w->slotOf];
        w->charge = chargeOf(next->job);
        pixelsInFlight_ += w->charge;
      }
    }
    for (RenderJob& job : dropped) {
      if (job.onCancelled) job.onCancelled();
    }
    for (auto& [job, error] : failed) job.done(std::nullopt, error);
    if (!next) continue;
    render(*w, next->job, next->submitted);
    if (!release(*w)) return;  // abandoned: this thread has been replaced
    queueCv_.notify_all();
  }
}

// Holds w.charge pixels of the budget; resizes it to the request's.
void FrameWorkers::render(Worker& w, RenderJob& job, Clock::time_point submitted) {
  const double queuedSeconds = secondsSince(submitted);
  auto cancel = [&job] {
    if (job.onCancelled) job.onCancelled();
  };
  std::optional<render::FrameRequest> request = job.take();
  if (!request || isCancelled(job)) return cancel();
  const std::size_t pixels = static_cast<std::size_t>(std::max(0, request->width)) *
                             static_cast<std::size_t>(std::max(0, request->height));
  if (pixels > options_.maxSessionPixels) {
    job.done(std::nullopt, "a frame of " + std::to_string(request->width) + "×" + std::to_string(request->height) +
                               " (" + std::to_string(pixels) + " pixels) is over the server's limit of " +
                               std::to_string(options_.maxSessionPixels) + " pixels per session (max-session-pixels)");
    return;
  }
  // Only EXR encodes the linear image; every other encoding needs RGBA8
  // alone, and a GPU backend then skips reading the linear image back.
  request->linearImage = job.encoding == FrameEncoding::Exr;
  // Once abandoned, the job's own callback is not called any more: it may
  // point into a server that has gone meanwhile.
  request->cancelled = [this, &w, &job, own = std::move(request->cancelled)] {
    return w.abandoned.load() || stopping_.load() || isCancelled(job) || (own && own());
  };
  std::shared_ptr<render::StageMark> stage = job.stage ? job.stage : std::make_shared<render::StageMark>();
  stage->enter(nullptr);
  request->stage = stage.get();
  {
    std::lock_guard lock(mutex_);
    w.stage = std::move(stage);
    pixelsInFlight_ = pixelsInFlight_ - w.charge + pixels;  // the session's size may have changed since submit
    w.charge = pixels;
    w.rendering = true;
    w.started = Clock::now();
    w.job = &job;
  }
  RenderedFrame out;
  out.queuedSeconds = queuedSeconds;
  std::string error;
  try {
    out.frame = job.renderer->renderer->render(*request);
  } catch (const std::exception& e) {
    error = std::string("render failed: ") + e.what();
  }
  if (!claim(w)) return;  // abandoned meanwhile: its session has had its error
  if (!error.empty()) {
    job.done(std::nullopt, error);
    return;
  }
  if (out.frame.cancelled || stopping_) return cancel();
  // The weights of the next frame's progress (frame_progress.h), any session's.
  job.renderer->setLastFrame({out.frame.stages, pixels});
  // Encoding goes to its own threads: the next frame can render meanwhile.
  encoders_.push([job = std::move(job), out = std::move(out)]() mutable {
    try {
      const auto t0 = Clock::now();
      out.encoded = job.encode ? job.encode(out.frame)
                               : encodeFrame(job.encoding, out.frame.rgba8, out.frame.width, out.frame.height,
                                             out.frame.image, job.jpegQuality);
      out.encodeSeconds = secondsSince(t0);
    } catch (const std::exception& e) {
      job.done(std::nullopt, std::string("encode failed: ") + e.what());
      return;
    }
    job.done(std::move(out), {});
  });
}

// Right after Renderer::render returned: whether the frame is still this
// thread's to answer (false: the watchdog abandoned it meanwhile).
bool FrameWorkers::claim(Worker& w) {
  std::lock_guard lock(mutex_);
  if (w.abandoned) return false;
  w.rendering = false;
  w.job = nullptr;
  return true;
}

// The job's device and pixels given back; false when this thread was left
// behind (its frame abandoned, or stop() did not wait for it): it must end.
bool FrameWorkers::release(Worker& w) {
  std::lock_guard lock(mutex_);
  if (w.holdsDevice) w.device->busy = false;
  w.holdsDevice = false;
  if (w.slotOf && --rendering_[w.slotOf] == 0) rendering_.erase(w.slotOf);
  w.slotOf = nullptr;
  pixelsInFlight_ -= w.charge;
  w.charge = 0;
  if (!w.abandoned) return true;
  // An abandoned frame came back after all: the device may be healthy again.
  // (Logged only before stop(): the log may belong to a server that has gone.)
  if (w.counted && --w.device->stuck == 0 && !stopping_) {
    log("device " + w.device->name + " (" + w.device->backend + ") is healthy again: its abandoned frame returned after " +
        formatSeconds(secondsSince(w.started)) + " s");
  }
  w.counted = false;
  w.rendering = false;
  if (left_.remove_if([&w](const std::shared_ptr<Worker>& p) { return p.get() == &w; }) > 0) noteLeftThreadReturned();
  w.exited = true;
  return false;
}

void FrameWorkers::watch() {
  const std::chrono::duration<double> deadline(options_.frameDeadlineSeconds);
  // A frame is abandoned at most an eighth of the deadline late (between 5
  // and 250 ms): a handful of wake-ups a second for a few workers.
  const auto period = std::clamp(std::chrono::duration_cast<std::chrono::milliseconds>(deadline / 8), 5ms, 250ms);
  std::unique_lock lock(mutex_);
  while (!stopping_) {
    watchCv_.wait_for(lock, period, [this] { return stopping_.load(); });
    if (stopping_) return;
    std::vector<std::pair<Done, std::string>> answers;
    const auto now = Clock::now();
    for (auto it = workers_.begin(); it != workers_.end();) {
      const std::shared_ptr<Worker> w = *it++;  // abandonLocked takes it out of workers_
      if (!w->rendering || now - w->started <= deadline) continue;
      std::string error;
      Done done = abandonLocked(w, error);
      answers.emplace_back(std::move(done), std::move(error));
    }
    if (answers.empty()) continue;
    lock.unlock();
    queueCv_.notify_all();  // pixels freed, a fresh worker, jobs of the device to fail
    for (auto& [done, error] : answers) {
      if (done) done(std::nullopt, error);
    }
    lock.lock();
  }
}

// The frame of `w` is past the deadline: its job's `done` (for the caller
// to answer with `error`, outside the lock), its pixels freed, its device
// unhealthy, its thread left behind and replaced. Under mutex_.
FrameWorkers::Done FrameWorkers::abandonLocked(const std::shared_ptr<Worker>& w, std::string& error) {
  // Set together in render(), under the lock, before the frame starts.
  HC_CHECK_EQ(w->rendering, true);
  HC_CHECK_NE(w->job, nullptr);
  HC_CHECK_NE(w->device, nullptr);
  Device& device = *w->device;
  const char* stage = w->stage->current();
  const std::string after = "after " + formatSeconds(options_.frameDeadlineSeconds) + " s in stage " + (stage ? stage : "unknown");
  error = "frame abandoned " + after + " on device " + device.name + " (frame-deadline); the device is marked unhealthy";
  device.reason = "a frame abandoned " + after;
  ++device.stuck;
  w->counted = true;
  w->abandoned = true;
  pixelsInFlight_ -= w->charge;
  w->charge = 0;
  Done done = std::move(w->job->done);
  w->job = nullptr;
  workers_.remove(w);
  left_.push_back(w);
  noteThreadLeftBehind();
  w->thread.detach();
  metrics_.framesAbandoned.fetch_add(1);
  spawnLocked();
  log("frame abandoned " + after + " on device " + device.name + " (" + device.backend +
      "): the device is unhealthy, its render thread is left behind and replaced (" + std::to_string(left_.size()) +
      " stuck)");
  return done;
}

std::size_t FrameWorkers::queued() const {
  std::lock_guard lock(mutex_);
  return queue_.size();
}

std::size_t FrameWorkers::pixelsInFlight() const {
  std::lock_guard lock(mutex_);
  return pixelsInFlight_;
}

bool FrameWorkers::atPixelBudget() const {
  std::lock_guard lock(mutex_);
  const std::size_t budget = options_.serverPixelBudget;
  return budgetWait_ || (budget && pixelsInFlight_ >= budget);
}

std::vector<DeviceStatus> FrameWorkers::devices() const {
  std::lock_guard lock(mutex_);
  std::vector<DeviceStatus> out;
  for (const auto& [key, d] : devices_) out.push_back({d.backend, d.name, d.stuck == 0, d.stuck == 0 ? "" : d.reason});
  return out;
}

std::vector<StuckRender> FrameWorkers::stuckRenders() const {
  std::lock_guard lock(mutex_);
  std::vector<StuckRender> out;
  for (const auto& w : left_) {
    const char* stage = w->stage->current();
    StuckRender s;
    if (w->rendering) {
      s.backend = w->device->backend;
      s.device = w->device->name;
      s.stage = stage ? stage : "unknown";
      s.seconds = secondsSince(w->started);
    } else {
      s.stage = "between frames";  // stop() did not wait for it to take its next job
    }
    out.push_back(std::move(s));
  }
  return out;
}

void FrameWorkers::stop(Clock::time_point graceUntil) {
  std::deque<Queued> dropped;  // callbacks destroyed outside the lock
  {
    std::lock_guard lock(mutex_);
    if (stopping_) return;
    stopping_ = true;
    dropped.swap(queue_);
  }
  queueCv_.notify_all();
  watchCv_.notify_all();
  if (watchdog_.joinable()) watchdog_.join();
  std::vector<std::shared_ptr<Worker>> finished;
  {
    std::unique_lock lock(mutex_);
    exitCv_.wait_until(lock, graceUntil, [this] {
      return std::all_of(workers_.begin(), workers_.end(), [](const auto& w) { return w->exited; });
    });
    for (const auto& w : workers_) {
      if (w->exited) {
        finished.push_back(w);
        continue;
      }
      // Still inside a render past the grace: not joined (it may never
      // return), left behind with what it holds.
      w->abandoned = true;
      if (w->rendering && w->device && !w->counted) {
        ++w->device->stuck;
        w->counted = true;
      }
      w->thread.detach();
      left_.push_back(w);
      noteThreadLeftBehind();
    }
    workers_.clear();
  }
  for (const auto& w : finished) w->thread.join();
  encoders_.stop();
}

}  // namespace haarcast::net

// The render service's frames (render_service.h): the job queue, the render
// threads, the server's pixel budget, the devices and the frame deadline.
//
//   devices   Renderers are grouped by device (backend() + deviceName()).
//             Renderers of one frame at a time (framesInFlight() 1: Vulkan
//             on a CPU device) take turns on their device's one busy flag;
//             a renderer of K frames in flight (Vulkan on a GPU) has up to K
//             of its frames rendering, whatever else is on its device. A job
//             that may not start yet is passed over, so it never holds a
//             worker while it waits, and a stuck device holds at most K workers.
//   deadline  A watchdog thread abandons a frame rendering longer than
//             Options::frameDeadlineSeconds: its session's `done` gets an
//             error naming the stage the frame was in (render::StageMark)
//             and the device, its pixels leave the budget, its worker
//             thread is left behind (detached) and replaced, and its device
//             turns unhealthy. Jobs for an unhealthy device fail at once.
//             When an abandoned frame returns after all, its thread drops
//             the frame and ends; the device is healthy again once none of
//             its abandoned frames is still out.
//   stop      Waits for the render threads until a grace deadline; a thread
//             still inside a render then is left behind, not joined.
//
// Every thread holds a shared_ptr to this object, so one left behind (inside
// a render that may never return) keeps everything it touches alive; it
// touches nothing outside it (the server's Metrics, the log) once stopping.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <list>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "haarcast/net/render_service.h"
#include "haarcast/render/frame_stage.h"
#include "task_queue.h"

namespace haarcast::net {

class FrameWorkers : public std::enable_shared_from_this<FrameWorkers> {
 public:
  using Clock = std::chrono::steady_clock;

  FrameWorkers(const RenderService::Options& options, Metrics& metrics);
  ~FrameWorkers();
  FrameWorkers(const FrameWorkers&) = delete;
  FrameWorkers& operator=(const FrameWorkers&) = delete;

  void start();  // the workers, the watchdog, the encoders
  void submit(RenderJob job);
  std::size_t queued() const;
  std::size_t pixelsInFlight() const;
  bool atPixelBudget() const;
  std::vector<DeviceStatus> devices() const;
  std::vector<StuckRender> stuckRenders() const;
  void stop(Clock::time_point graceUntil);

 private:
  struct Device {
    std::string backend;
    std::string name;
    bool busy = false;       // a frame of a renderer that cannot render concurrently is on it
    std::size_t stuck = 0;   // its abandoned frames that have not returned
    std::string reason;      // the last abandonment: why it is unhealthy
  };
  struct Queued {
    RenderJob job;
    Clock::time_point submitted;
    Device* device = nullptr;
  };
  // One render thread. Fields from `stage` on are under mutex_ (`abandoned`
  // is also read without it).
  struct Worker {
    std::thread thread;
    // The stage its frame is in: the job's mark (RenderJob::stage) or a
    // fresh one, set under mutex_ before the frame starts.
    std::shared_ptr<render::StageMark> stage = std::make_shared<render::StageMark>();
    std::atomic<bool> abandoned{false};     // left behind: it must not answer its job, nor take another
    bool rendering = false;                 // inside Renderer::render
    bool counted = false;                   // counted in its device's `stuck`
    bool exited = false;                    // its loop has ended (stop() may join it)
    RenderJob* job = nullptr;               // the job rendering now (on the thread's stack)
    Device* device = nullptr;
    bool holdsDevice = false;               // holds device->busy
    const render::Renderer* slotOf = nullptr;  // the renderer whose frame slot it holds (K frames in flight)
    std::size_t charge = 0;                 // its share of the pixel budget
    Clock::time_point started;              // its render's start
  };
  using Failed = std::pair<RenderJob, std::string>;  // a job answered with an error

  void workerLoop(const std::shared_ptr<Worker>& w);
  void spawnLocked();
  std::optional<Queued> pickLocked(std::vector<RenderJob>& dropped, std::vector<Failed>& failed);
  std::size_t chargeOf(const RenderJob& job) const;
  std::size_t slotsInUse(const render::Renderer& renderer) const;  // under mutex_
  void render(Worker& w, RenderJob& job, Clock::time_point submitted);
  bool claim(Worker& w);
  bool release(Worker& w);
  void watch();
  using Done = decltype(RenderJob::done);
  Done abandonLocked(const std::shared_ptr<Worker>& w, std::string& error);
  void log(const std::string& line) const;
  static std::string unhealthyError(const Device& d);

  RenderService::Options options_;
  Metrics& metrics_;

  mutable std::mutex mutex_;
  std::condition_variable queueCv_;  // a job queued, a worker freed, stop
  std::condition_variable watchCv_;  // stop, for the watchdog
  std::condition_variable exitCv_;   // a worker's loop ended, for stop()
  std::deque<Queued> queue_;
  std::map<std::pair<std::string, std::string>, Device> devices_;  // by (backend, name); never erased
  std::map<const render::Renderer*, std::size_t> rendering_;  // frames rendering per renderer of K > 1 frames in flight (0: erased)
  std::size_t pixelsInFlight_ = 0;
  bool budgetWait_ = false;          // the oldest startable job waits for the budget
  std::atomic<bool> stopping_{false};
  std::list<std::shared_ptr<Worker>> workers_;  // the live ones
  std::list<std::shared_ptr<Worker>> left_;     // left behind, not returned
  std::thread watchdog_;
  TaskQueue encoders_;
};

}  // namespace haarcast::net

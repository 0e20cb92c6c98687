#include "haarcast/net/render_service.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <future>
#include <list>
#include <limits>
#include <map>
#include <mutex>
#include <set>
#include <stdexcept>
#include <thread>
#include <utility>

#include "frame_workers.h"
#include "haarcast/net/left_behind.h"

namespace haarcast::net {
namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

void checkOptions(const RenderService::Options& o) {
  auto bad = [](const std::string& what) { throw std::invalid_argument("RenderService options: " + what); };
  if (o.workers < 1) bad("workers must be at least 1 (got " + std::to_string(o.workers) + ")");
  if (o.encoders < 1) bad("encoders must be at least 1 (got " + std::to_string(o.encoders) + ")");
  if (o.maxSessionPixels < 1) bad("maxSessionPixels must be at least 1");
  if (o.maxQueuedBuilds < 1) bad("maxQueuedBuilds must be at least 1");
  if (!(o.progressIntervalSeconds >= 0.0)) bad("progressIntervalSeconds must be at least 0");
  if (!(o.frameDeadlineSeconds >= 0.0)) bad("frameDeadlineSeconds must be at least 0 (0: none)");
  if (!(o.stopGraceSeconds >= 0.0)) bad("stopGraceSeconds must be at least 0");
}

// A prepare's answer, made under the cache lock and given outside it.
using Answer = std::pair<RenderService::PrepareDone, PrepareOutcome>;

// What prepare() hands out once the lock is released: the answers, and the
// running build's latest progress for the prepare that joined it.
struct PrepareResult {
  std::vector<Answer> answers;
  RenderService::ProgressSink progressSink;
  std::optional<BuildProgressUpdate> progress;
};

}  // namespace

struct RenderService::Impl {
  AbandonableRendererBuilder builder;
  Options options;
  Metrics& metrics;

  // ---- Renderers: the cache, the builds, who waits for what --------------
  // A build of one key, queued or running, with the prepares waiting for it.
  struct Waiter {
    std::string owner;
    PrepareDone done;
    ProgressSink progress;  // may be empty
  };
  struct Build {
    SessionConfig config;
    std::string key;
    std::vector<Waiter> waiters;
    std::atomic<bool> abandoned{false};
    // Set when the builder thread takes it; under cacheMutex. `latest` is
    // the last progress update published: what a prepare joining the
    // running build gets at once.
    Clock::time_point started;
    std::optional<BuildProgressUpdate> latest;
  };
  std::mutex cacheMutex;
  std::list<std::shared_ptr<PreparedRenderer>> ready;  // LRU order, front = most recent
  std::map<std::string, std::shared_ptr<Build>> builds;  // by key: the one new waiters join
  std::deque<std::shared_ptr<Build>> buildQueue;         // not yet running, in arrival order
  // Owner → the number of the last build started for it (builds count from
  // 1). The next build is the queued one whose most starved waiter was served
  // longest ago, so a session flooding settings cannot keep a newcomer's
  // first build behind its own latest one: a new owner waits at most for the
  // build running when it arrives.
  std::map<std::string, std::uint64_t> ownerServed;
  std::uint64_t buildsStarted = 0;
  std::map<std::string, std::shared_ptr<Build>> ownerWaits;  // owner → the build it waits for
  std::condition_variable buildCv;
  bool buildsStopping = false;
  std::shared_ptr<Build> runningBuild;  // taken from the queue by the builder thread
  std::thread builderThread;

  // Set when the builder thread's loop has ended (stop() may join it).
  std::promise<void> builderExitedPromise;
  std::atomic<bool> builderLeft{false};  // stop() did not wait for it: reported with stuckRenders()
  std::future<void> builderExited = builderExitedPromise.get_future();

  // The frames: queue, render threads, devices, deadline (frame_workers.h).
  std::shared_ptr<FrameWorkers> frames;

  Impl(AbandonableRendererBuilder b, Options o, Metrics& m)
      : builder(std::move(b)), options(o), metrics(m), frames(std::make_shared<FrameWorkers>(options, m)) {}

  // -------------------------------------------------------------- builds

  // Removes the owner's waiting prepare (answered Superseded when `answers`
  // is given, else dropped); a build then waited for by nobody is dropped
  // from the queue, or abandoned when running. Under cacheMutex.
  void detachOwner(const std::string& owner, std::vector<Answer>* answers) {
    const auto it = ownerWaits.find(owner);
    if (it == ownerWaits.end()) return;
    const std::shared_ptr<Build> build = it->second;
    ownerWaits.erase(it);
    auto& w = build->waiters;
    for (auto k = w.begin(); k != w.end(); ++k) {
      if (k->owner != owner) continue;
      if (answers) answers->push_back({std::move(k->done), {PrepareStatus::Superseded, nullptr, {}}});
      w.erase(k);
      break;
    }
    if (!w.empty()) return;
    if (build == runningBuild) {
      build->abandoned = true;
    } else {
      buildQueue.erase(std::remove(buildQueue.begin(), buildQueue.end(), build), buildQueue.end());
    }
    if (const auto b = builds.find(build->key); b != builds.end() && b->second == build) builds.erase(b);
  }

  // When the owner already waits for a build of `key`, its new callbacks
  // take the old ones' place (answered Superseded) and the build goes on.
  // Under cacheMutex.
  bool replaceWaiter(const std::string& owner, const std::string& key, PrepareDone& done, ProgressSink& progress,
                     PrepareResult& result) {
    const auto it = ownerWaits.find(owner);
    if (it == ownerWaits.end() || it->second->key != key || it->second->abandoned) return false;
    for (Waiter& w : it->second->waiters) {
      if (w.owner != owner) continue;
      result.answers.push_back({std::exchange(w.done, std::move(done)), {PrepareStatus::Superseded, nullptr, {}}});
      w.progress = std::move(progress);
      joinProgress(*it->second, w.progress, result);
      return true;
    }
    return false;
  }

  // The build's latest progress for a prepare that has just joined it (its
  // elapsed time brought up to now). Under cacheMutex.
  static void joinProgress(const Build& build, const ProgressSink& sink, PrepareResult& result) {
    if (!sink || !build.latest) return;
    result.progressSink = sink;
    result.progress = build.latest;
    result.progress->elapsedSeconds = secondsSince(build.started);
  }

  // The cached renderer of `key`, made the most recently used; null if none.
  // Under cacheMutex.
  std::shared_ptr<PreparedRenderer> cachedLocked(const std::string& key) {
    for (auto it = ready.begin(); it != ready.end(); ++it) {
      if ((*it)->key == key) {
        ready.splice(ready.begin(), ready, it);
        return ready.front();
      }
    }
    return nullptr;
  }

  PrepareResult prepare(const SessionConfig& config, const std::string& owner, PrepareDone done, ProgressSink progress) {
    PrepareResult result;
    std::vector<Answer>& answers = result.answers;
    const std::string key = config.rendererKey();
    std::lock_guard lock(cacheMutex);
    if (!owner.empty()) {  // the latest wins
      if (replaceWaiter(owner, key, done, progress, result)) return result;
      detachOwner(owner, &answers);
    }
    if (buildsStopping) {
      answers.push_back({std::move(done), {PrepareStatus::Refused, nullptr, "the render service is stopping"}});
      return result;
    }
    if (auto cached = cachedLocked(key)) {
      answers.push_back({std::move(done), {PrepareStatus::Ready, std::move(cached), {}}});
      return result;
    }
    std::shared_ptr<Build>& build = builds[key];  // an abandoned build is not in `builds`
    if (!build) {
      if (buildQueue.size() >= options.maxQueuedBuilds) {
        builds.erase(key);
        answers.push_back({std::move(done),
                           {PrepareStatus::Refused, nullptr,
                            "the server has " + std::to_string(buildQueue.size()) +
                                " renderer builds queued, its limit (max-queued-builds); try again later"}});
        return result;
      }
      build = std::make_shared<Build>();
      build->config = config;
      build->key = key;
      buildQueue.push_back(build);
      buildCv.notify_one();
    }
    joinProgress(*build, progress, result);
    build->waiters.push_back({owner, std::move(done), std::move(progress)});
    if (!owner.empty()) ownerWaits[owner] = build;
    return result;
  }

  // The queued build to start next (see ownerServed); the queue is not empty.
  // Under cacheMutex.
  std::deque<std::shared_ptr<Build>>::iterator fairestBuild() {
    auto served = [&](const Build& b) {
      std::uint64_t least = std::numeric_limits<std::uint64_t>::max();
      for (const auto& waiter : b.waiters) {
        const auto it = ownerServed.find(waiter.owner);
        least = std::min(least, it == ownerServed.end() ? std::uint64_t{0} : it->second);
      }
      return least;
    };
    auto best = buildQueue.begin();
    std::uint64_t bestServed = served(**best);
    for (auto it = std::next(best); it != buildQueue.end() && bestServed > 0; ++it) {
      if (const std::uint64_t s = served(**it); s < bestServed) {
        best = it;
        bestServed = s;
      }
    }
    return best;
  }

  void builderLoop() {
    for (;;) {
      std::shared_ptr<Build> build;
      std::shared_ptr<PreparedRenderer> cached;
      {
        std::unique_lock lock(cacheMutex);
        buildCv.wait(lock, [&] { return buildsStopping || !buildQueue.empty(); });
        if (buildsStopping) return;
        const auto next = fairestBuild();
        build = std::move(*next);
        buildQueue.erase(next);
        ++buildsStarted;
        for (const auto& waiter : build->waiters) {
          if (!waiter.owner.empty()) ownerServed[waiter.owner] = buildsStarted;
        }
        runningBuild = build;
        build->started = Clock::now();
        cached = cachedLocked(build->key);  // an abandoned build of this key may have finished meanwhile
      }
      std::shared_ptr<PreparedRenderer> renderer = cached;
      std::string error;
      if (!renderer) {
        render::BuildPlan plan;
        try {
          if (options.planner) plan = options.planner(build->config);
        } catch (...) {
          // A plan is information: the build says what is wrong with the config.
        }
        BuildProgressTracker tracker(build->started, options.progressIntervalSeconds, std::move(plan));
        const render::RenderProgress progress = [&](const std::string& stage, std::size_t done, std::size_t total) {
          if (auto update = tracker.step(stage, done, total, Clock::now())) publish(*build, std::move(*update));
        };
        try {
          renderer = builder(build->config, [&build] { return build->abandoned.load(); }, progress);
          if (!renderer || !renderer->renderer) error = "the renderer builder returned nothing";
        } catch (const std::exception& e) {
          error = e.what();
        } catch (...) {
          error = "the renderer builder failed";
        }
        if (!error.empty()) renderer.reset();
      }
      finishBuild(build, std::move(renderer), error, !cached);
    }
  }

  // One progress update to every waiter of the running build, outside the
  // lock; kept for those that join later. On the builder thread.
  void publish(Build& build, BuildProgressUpdate update) {
    std::vector<ProgressSink> sinks;
    {
      std::lock_guard lock(cacheMutex);
      if (buildsStopping) return;  // the sinks may belong to sessions that have gone
      for (const Waiter& w : build.waiters) {
        if (w.progress) sinks.push_back(w.progress);
      }
      build.latest = update;
    }
    for (const ProgressSink& sink : sinks) {
      try {
        sink(update);
      } catch (...) {
        // Progress is information: a sink that fails must not fail the build.
      }
    }
  }

  void finishBuild(const std::shared_ptr<Build>& build, std::shared_ptr<PreparedRenderer> renderer,
                   const std::string& error, bool built) {
    std::vector<Answer> answers;
    {
      std::lock_guard lock(cacheMutex);
      runningBuild.reset();
      if (const auto b = builds.find(build->key); b != builds.end() && b->second == build) builds.erase(b);
      // Stopping: the waiters are dropped unanswered, and nothing of the
      // server's is touched (a build left behind by stop() may end after the
      // server has gone).
      if (buildsStopping) return;
      if (renderer && built) {
        // Cached even when abandoned: another session may want it next.
        renderer->key = build->key;
        metrics.renderersBuilt.fetch_add(1);
        const std::string rays = renderer->renderer->rays();
        (rays == "device" ? metrics.renderersRaysDevice : rays == "host" ? metrics.renderersRaysHost : metrics.renderersRaysNone)
            .fetch_add(1);
        ready.push_front(renderer);
        while (ready.size() > options.maxRenderers) ready.pop_back();  // sessions keep theirs alive
      }
      for (Waiter& w : build->waiters) {
        if (const auto o = ownerWaits.find(w.owner); o != ownerWaits.end() && o->second == build) ownerWaits.erase(o);
        answers.push_back({std::move(w.done), renderer ? PrepareOutcome{PrepareStatus::Ready, renderer, {}}
                                                       : PrepareOutcome{PrepareStatus::Failed, nullptr, error}});
      }
      build->waiters.clear();
    }
    for (auto& [done, outcome] : answers) done(std::move(outcome));
  }
};

AbandonableRendererBuilder asAbandonable(RendererBuilder builder) {
  if (!builder) return {};
  return [builder = std::move(builder)](const SessionConfig& config, const std::function<bool()>&,
                                        const render::RenderProgress&) {
    return builder(config);  // cannot stop early: an abandoned build finishes into the cache
  };
}

RenderService::RenderService(RendererBuilder builder, Options options, Metrics& metrics)
    : RenderService(asAbandonable(std::move(builder)), options, metrics) {}

RenderService::RenderService(AbandonableRendererBuilder builder, Options options, Metrics& metrics) {
  checkOptions(options);
  if (!builder) throw std::invalid_argument("RenderService: no renderer builder");
  impl_ = std::make_shared<Impl>(std::move(builder), options, metrics);
  impl_->builderThread = std::thread([impl = impl_] {
    impl->builderLoop();
    impl->builderExitedPromise.set_value();
    // Left behind by stop() and back after all: no longer counted (a return
    // just before stop() set the flag stays counted, which only makes the
    // process's exit skip its destructors).
    if (impl->builderLeft.exchange(false)) noteLeftThreadReturned();
  });
  impl_->frames->start();
}

RenderService::~RenderService() { stop(); }

void RenderService::prepare(const SessionConfig& config, const std::string& owner, PrepareDone done,
                            ProgressSink progress) {
  if (!done) throw std::invalid_argument("RenderService::prepare: no callback");
  PrepareResult result = impl_->prepare(config, owner, std::move(done), std::move(progress));
  if (result.progress) result.progressSink(*result.progress);
  for (auto& [callback, outcome] : result.answers) callback(std::move(outcome));
}

void RenderService::prepare(const SessionConfig& config, PrepareCallback done) {
  if (!done) throw std::invalid_argument("RenderService::prepare: no callback");
  prepare(config, std::string(), [done = std::move(done)](PrepareOutcome o) {
    done(std::move(o.renderer), std::move(o.error));
  });
}

void RenderService::withdraw(const std::string& owner) {
  if (owner.empty()) return;  // nobody's prepares are never withdrawn
  std::lock_guard lock(impl_->cacheMutex);
  impl_->detachOwner(owner, nullptr);
  impl_->ownerServed.erase(owner);  // a closed session's turn is not kept
}

void RenderService::submit(RenderJob job) {
  if (!job.renderer || !job.renderer->renderer) throw std::invalid_argument("RenderService::submit: a job without a renderer");
  impl_->frames->submit(std::move(job));
}

std::size_t RenderService::queued() const { return impl_->frames->queued(); }

std::size_t RenderService::queuedBuilds() const {
  std::lock_guard lock(impl_->cacheMutex);
  return impl_->buildQueue.size();
}

std::size_t RenderService::pixelsInFlight() const { return impl_->frames->pixelsInFlight(); }

bool RenderService::atPixelBudget() const { return impl_->frames->atPixelBudget(); }

std::vector<DeviceStatus> RenderService::devices() const { return impl_->frames->devices(); }

std::vector<StuckRender> RenderService::stuckRenders() const {
  std::vector<StuckRender> stuck = impl_->frames->stuckRenders();
  if (impl_->builderLeft) stuck.push_back({"", "", "a renderer build", 0.0});
  return stuck;
}

void RenderService::stop() {
  if (!impl_) return;
  stop(Clock::now() + std::chrono::duration_cast<Clock::duration>(
                         std::chrono::duration<double>(impl_->options.stopGraceSeconds)));
}

void RenderService::stop(Clock::time_point graceUntil) {
  if (!impl_) return;
  Impl& s = *impl_;
  // Flags first, then joins: a running build and the running frames stop
  // together, at their next stage, tile or batch.
  std::deque<std::shared_ptr<Impl::Build>> droppedBuilds;  // callbacks destroyed outside the locks
  {
    std::lock_guard lock(s.cacheMutex);
    s.buildsStopping = true;
    if (s.runningBuild) s.runningBuild->abandoned = true;
    droppedBuilds.swap(s.buildQueue);
    s.builds.clear();
    s.ownerWaits.clear();
  }
  s.buildCv.notify_all();
  s.frames->stop(graceUntil);
  // A build stuck past the grace (a renderer's warm-up frame inside a
  // library call) is left behind like a render: it holds the Impl.
  if (s.builderThread.joinable()) {
    if (s.builderExited.wait_until(graceUntil) == std::future_status::ready) {
      s.builderThread.join();
    } else {
      s.builderThread.detach();
      noteThreadLeftBehind();
      s.builderLeft = true;
      if (s.options.log) s.options.log("a renderer build was still running after the stop grace: left behind");
    }
  }
}

}  // namespace haarcast::net

#include "haarcast/net/render_service.h"

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <list>
#include <map>
#include <set>
#include <stdexcept>
#include <mutex>
#include <thread>

#include "haarcast/net/encode.h"

namespace haarcast::net {
namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// A FIFO of tasks served by a fixed set of threads.
class TaskQueue {
 public:
  void start(int threads) {
    for (int i = 0; i < threads; ++i) threads_.emplace_back([this] { loop(); });
  }
  void push(std::function<void()> task) {
    {
      std::lock_guard lock(mutex_);
      if (stopping_) return;
      tasks_.push_back(std::move(task));
    }
    cv_.notify_one();
  }
  std::size_t size() const {
    std::lock_guard lock(mutex_);
    return tasks_.size();
  }
  void stop() {
    {
      std::lock_guard lock(mutex_);
      stopping_ = true;
      tasks_.clear();
    }
    cv_.notify_all();
    for (auto& t : threads_) {
      if (t.joinable()) t.join();
    }
    threads_.clear();
  }

 private:
  void loop() {
    for (;;) {
      std::function<void()> task;
      {
        std::unique_lock lock(mutex_);
        cv_.wait(lock, [this] { return stopping_ || !tasks_.empty(); });
        if (stopping_) return;
        task = std::move(tasks_.front());
        tasks_.pop_front();
      }
      task();
    }
  }

  mutable std::mutex mutex_;
  std::condition_variable cv_;
  std::deque<std::function<void()>> tasks_;
  std::vector<std::thread> threads_;
  bool stopping_ = false;
};

}  // namespace

struct RenderService::Impl {
  RendererBuilder builder;
  Options options;
  Metrics& metrics;

  // The cache: ready renderers in LRU order (front = most recent), and the
  // configs being built with the callbacks waiting for them.
  std::mutex cacheMutex;
  std::list<std::shared_ptr<PreparedRenderer>> ready;
  std::map<std::string, std::vector<PrepareCallback>> building;

  // The frame queue. A worker takes the oldest job whose renderer is idle:
  // renderers are not thread-safe, and a worker waiting on a busy one's lock
  // instead would let whichever thread wins the lock jump the queue.
  struct Queued {
    RenderJob job;
    Clock::time_point submitted;
  };
  std::mutex queueMutex;
  std::condition_variable queueCv;
  std::deque<Queued> queue;
  std::set<const PreparedRenderer*> busy;
  bool stopping = false;
  std::vector<std::thread> workers;

  TaskQueue builderQueue, encodeQueue;

  Impl(RendererBuilder b, Options o, Metrics& m) : builder(std::move(b)), options(o), metrics(m) {}

  void workerLoop() {
    for (;;) {
      Queued next;
      {
        std::unique_lock lock(queueMutex);
        std::deque<Queued>::iterator it;
        queueCv.wait(lock, [&] {
          if (stopping) return true;
          it = std::find_if(queue.begin(), queue.end(),
                            [&](const Queued& q) { return !busy.count(q.job.renderer.get()); });
          return it != queue.end();
        });
        if (stopping) return;
        next = std::move(*it);
        queue.erase(it);
        busy.insert(next.job.renderer.get());
      }
      const PreparedRenderer* renderer = next.job.renderer.get();
      render(next.job, next.submitted);
      {
        std::lock_guard lock(queueMutex);
        busy.erase(renderer);
      }
      queueCv.notify_all();
    }
  }

  void build(const SessionConfig& config) {
    std::shared_ptr<PreparedRenderer> renderer;
    std::string error;
    try {
      renderer = builder(config);
      if (!renderer || !renderer->renderer) error = "the renderer builder returned nothing";
    } catch (const std::exception& e) {
      error = e.what();
    }
    std::vector<PrepareCallback> waiting;
    {
      std::lock_guard lock(cacheMutex);
      auto it = building.find(config.rendererKey());
      if (it != building.end()) {
        waiting = std::move(it->second);
        building.erase(it);
      }
      if (error.empty()) {
        renderer->key = config.rendererKey();
        metrics.renderersBuilt.fetch_add(1);
        ready.push_front(renderer);
        while (ready.size() > options.maxRenderers) ready.pop_back();  // sessions keep theirs alive
      }
    }
    for (auto& cb : waiting) cb(error.empty() ? renderer : nullptr, error);
  }

  void render(RenderJob& job, Clock::time_point submitted) {
    const double queuedSeconds = secondsSince(submitted);
    std::optional<render::FrameRequest> request = job.take();
    if (!request) return;  // the session has gone
    // Only EXR encodes the linear image; every other encoding needs RGBA8
    // alone, and a GPU backend then skips reading the linear image back.
    request->linearImage = job.encoding == FrameEncoding::Exr;
    RenderedFrame out;
    out.queuedSeconds = queuedSeconds;
    try {
      out.frame = job.renderer->renderer->render(*request);  // this worker alone holds the renderer
    } catch (const std::exception& e) {
      job.done(std::nullopt, std::string("render failed: ") + e.what());
      return;
    }
    // Encoding goes to its own threads: the next frame can render meanwhile.
    encodeQueue.push([job = std::move(job), out = std::move(out)]() mutable {
      try {
        const auto t0 = Clock::now();
        out.encoded = encodeFrame(job.encoding, out.frame.rgba8, out.frame.width, out.frame.height, out.frame.image,
                                  job.jpegQuality);
        out.encodeSeconds = secondsSince(t0);
      } catch (const std::exception& e) {
        job.done(std::nullopt, std::string("encode failed: ") + e.what());
        return;
      }
      job.done(std::move(out), {});
    });
  }
};

RenderService::RenderService(RendererBuilder builder, Options options, Metrics& metrics)
    : impl_(std::make_unique<Impl>(std::move(builder), options, metrics)) {
  impl_->builderQueue.start(1);
  for (int i = 0; i < std::max(1, options.workers); ++i) {
    impl_->workers.emplace_back([impl = impl_.get()] { impl->workerLoop(); });
  }
  impl_->encodeQueue.start(std::max(1, options.encoders));
}

RenderService::~RenderService() { stop(); }

void RenderService::prepare(const SessionConfig& config, PrepareCallback done) {
  const std::string key = config.rendererKey();
  std::shared_ptr<PreparedRenderer> cached;
  {
    std::lock_guard lock(impl_->cacheMutex);
    for (auto it = impl_->ready.begin(); it != impl_->ready.end(); ++it) {
      if ((*it)->key == key) {
        cached = *it;
        impl_->ready.splice(impl_->ready.begin(), impl_->ready, it);  // most recently used
        break;
      }
    }
    if (!cached) {
      auto [it, fresh] = impl_->building.try_emplace(key);
      it->second.push_back(std::move(done));
      if (fresh) impl_->builderQueue.push([impl = impl_.get(), config] { impl->build(config); });
      return;
    }
  }
  done(cached, {});
}

void RenderService::submit(RenderJob job) {
  if (!job.renderer) throw std::invalid_argument("RenderService::submit: a job without a renderer");
  {
    std::lock_guard lock(impl_->queueMutex);
    if (impl_->stopping) return;
    impl_->queue.push_back({std::move(job), Clock::now()});
  }
  impl_->queueCv.notify_all();
}

std::size_t RenderService::queued() const {
  std::lock_guard lock(impl_->queueMutex);
  return impl_->queue.size();
}

void RenderService::stop() {
  if (!impl_) return;
  impl_->builderQueue.stop();
  {
    std::lock_guard lock(impl_->queueMutex);
    impl_->stopping = true;
    impl_->queue.clear();
  }
  impl_->queueCv.notify_all();
  for (auto& t : impl_->workers) {
    if (t.joinable()) t.join();
  }
  impl_->workers.clear();
  impl_->encodeQueue.stop();
}

}  // namespace haarcast::net

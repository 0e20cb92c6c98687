// How a transport (ws_session.cpp, grpc_session.cpp) hands its
// RenderSession's renderer builds and frames to the render service, and
// posts the answers back to its strand. The two transports differ in bytes
// and timers, not in this, so it is written once.
//
// `Transport` has: executor() (its strand), renderSession(), gone() (read on
// the strand), sessionId(), and derives from enable_shared_from_this. Jobs
// hold it weakly: a session that has gone is not kept alive by its frames.
#pragma once

#include <chrono>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <utility>

#include <boost/asio/post.hpp>

#include "haarcast/net/render_session.h"
#include "server_impl.h"

namespace haarcast::net {

// A build's progress on its way from the builder thread to one session's
// strand: at most one post is pending per session, and it carries the
// latest update when it runs, so a busy strand never piles up stale ones.
struct ProgressMailbox {
  std::mutex mutex;
  std::optional<BuildProgressUpdate> latest;
  bool posted = false;
};

template <class Transport>
RenderService::ProgressSink progressSink(const std::weak_ptr<Transport>& weak, const std::string& key) {
  return [weak, key, mailbox = std::make_shared<ProgressMailbox>()](const BuildProgressUpdate& update) {
    auto self = weak.lock();
    if (!self) return;
    {
      std::lock_guard lock(mailbox->mutex);
      mailbox->latest = update;
      if (mailbox->posted) return;  // the pending post takes this one
      mailbox->posted = true;
    }
    boost::asio::post(self->executor(), [self, key, mailbox] {
      std::optional<BuildProgressUpdate> latest;
      {
        std::lock_guard lock(mailbox->mutex);
        latest.swap(mailbox->latest);
        mailbox->posted = false;
      }
      if (latest && !self->gone()) self->renderSession().onBuildProgress(key, *latest);
    });
  };
}

// Build or find the renderer for `config` → RenderSession::onPrepared on the
// strand, and its progress while it is built → RenderSession::onBuildProgress.
template <class Transport>
void submitPrepare(Server::Impl& server, const std::shared_ptr<Transport>& transport, const SessionConfig& config) {
  // Per session the latest prepare wins (render_service.h): an earlier one
  // is answered Superseded, and onPrepared ignores a key that is not the
  // config's anyway.
  std::weak_ptr<Transport> weak = transport;
  const std::string key = config.rendererKey();
  server.renderService->prepare(config, transport->sessionId(), [weak, key](PrepareOutcome o) {
    if (o.status == PrepareStatus::Superseded) return;
    auto self = weak.lock();
    if (!self) return;
    // Refused: the server's build queue is full, which is the server's
    // load, not the client's mistake.
    const v1::ErrorCode code =
        o.status == PrepareStatus::Refused ? v1::ERROR_CODE_OVERLOADED : v1::ERROR_CODE_RENDER_FAILED;
    if (o.status != PrepareStatus::Ready) o.renderer.reset();
    boost::asio::post(self->executor(), [self, key, code, o = std::move(o)]() mutable {
      if (!self->gone()) self->renderSession().onPrepared(key, std::move(o.renderer), o.error, Clock::now(), code);
    });
  }, progressSink(weak, key));
}

// Render `order` → RenderSession::onRendered (or onCancelled) on the strand.
template <class Transport>
void submitFrame(Server::Impl& server, const std::shared_ptr<Transport>& transport, FrameOrder order) {
  std::weak_ptr<Transport> weak = transport;
  RenderJob job;
  job.renderer = std::move(order.renderer);
  job.encoding = order.encoding;
  job.jpegQuality = order.jpegQuality;
  job.pixels = order.pixels;
  job.encode = std::move(order.encode);
  // The context's mark, kept alive with it (aliasing): the session reads it
  // for FrameProgress while the worker's render moves it on.
  job.stage = std::shared_ptr<render::StageMark>(order.context, &order.context->stage);
  // Polled by a render worker at every tile or batch boundary: atomics and
  // a weak pointer only, never the session's strand or the service's lock.
  // The server's `stopping` outlives the service's threads (server_impl.h:
  // the service is destroyed first).
  job.cancelled = [weak, context = order.context, &stopping = server.stopping] {
    return context->cancelled.load() || stopping.load() || weak.expired();
  };
  job.take = [weak, context = order.context]() -> std::optional<render::FrameRequest> {
    const auto self = weak.lock();
    if (!self) return std::nullopt;
    return self->renderSession().takeRequest(*context);
  };
  job.done = [weak, context = order.context](std::optional<RenderedFrame> frame, std::string error) {
    if (auto self = weak.lock()) {
      boost::asio::post(self->executor(), [self, context, frame = std::move(frame), error = std::move(error)]() mutable {
        self->renderSession().onRendered(*context, std::move(frame), error, Clock::now());
      });
    }
  };
  job.onCancelled = [weak, context = order.context, &metrics = server.metrics] {
    metrics.framesCancelled.fetch_add(1);  // also when the session has gone
    if (auto self = weak.lock()) {
      boost::asio::post(self->executor(), [self, context] { self->renderSession().onCancelled(*context, Clock::now()); });
    }
  };
  server.renderService->submit(std::move(job));
}

// The watchdog both transports run on each tick: why to cut the session —
// one write in flight past writeStallSeconds (the client stopped reading)
// or a close not done within drainSeconds — with the metrics counted, or
// nullptr when it may go on.
inline const char* watchdogCut(Server::Impl& server, bool writing, Clock::time_point writeStarted, bool closeRequested,
                               Clock::time_point closeAt, Clock::time_point now) {
  auto seconds = [](Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); };
  if (writing && seconds(writeStarted, now) > server.options.writeStallSeconds) {
    server.metrics.addError(errorLabel(v1::ERROR_CODE_TIMEOUT));  // no Error can reach a client that does not read
    server.metrics.addTimeout("write");
    server.metrics.addCut("write_stall");
    return "a write has not completed for too long (the client stopped reading)";
  }
  if (closeRequested && seconds(closeAt, now) > server.options.drainSeconds) {
    server.metrics.addTimeout("close");
    return "the close did not complete in time";
  }
  return nullptr;
}

// A transport's pre-Hello slot given to a newcomer from another address
// while the budget is full (admission.h): Transport::evicted() runs on its
// strand. Returns Slot::onEvicted's answer: false when the slot was taken
// already, and the caller ends the transport at once.
template <class Transport>
bool endOnEviction(Admission::Slot& pending, const std::shared_ptr<Transport>& transport) {
  return pending.onEvicted([weak = std::weak_ptr<Transport>(transport), executor = transport->executor()] {
    boost::asio::post(executor, [weak] {
      if (auto self = weak.lock()) self->evicted();
    });
  });
}

// What an evicted transport counts before it ends: its slot no longer
// (the eviction uncounted it in Admission already), and the cut.
inline void countEviction(Server::Impl& server, Admission::Slot& pending) {
  if (pending) {
    pending.release();
    server.metrics.pending.fetch_sub(1);
  }
  server.metrics.addCut("pending_evicted");
}

// The session's last log line.
inline void logClosed(Server::Impl& server, const std::string& id, const RenderSession& session) {
  server.log("%s: closed (%llu frames, %llu dropped, %llu bytes)", id.c_str(),
             static_cast<unsigned long long>(session.framesSent()), static_cast<unsigned long long>(session.framesDropped()),
             static_cast<unsigned long long>(session.bytesSent()));
}

}  // namespace haarcast::net

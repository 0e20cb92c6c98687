// The gRPC port's HTTP/2 guard over byte strings and a made-up clock: the
// preface, stream and reset rates per connection and per address, header
// blocks, frames split anywhere, and the GOAWAY it sends.
#include "haarcast/net/http2_guard.h"

#include "http2_frames.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace haarcast::net {
namespace {

using namespace std::chrono_literals;

std::string frame(std::uint8_t type, std::uint8_t flags, std::uint32_t stream, std::size_t length) {
  return test::http2FrameHeader(length, type, flags, stream) + std::string(length, '\x01');
}

std::string headers(std::uint32_t stream) { return frame(http2::kHeaders, http2::kEndHeaders, stream, 20); }
std::string reset(std::uint32_t stream) { return frame(http2::kRstStream, 0, stream, 4); }

std::span<const std::uint8_t> bytesOf(const std::string& s) {
  return {reinterpret_cast<const std::uint8_t*>(s.data()), s.size()};
}

// Feeds `bytes` in pieces of `piece` bytes; the first abuse, if any.
std::optional<Http2Abuse> feedIn(Http2Guard& g, const std::string& bytes, std::size_t piece, Clock::time_point now) {
  for (std::size_t at = 0; at < bytes.size(); at += piece) {
    if (auto abuse = g.feed(bytesOf(bytes.substr(at, piece)), now)) return abuse;
  }
  return std::nullopt;
}

const Clock::time_point t0 = Clock::time_point{} + 1000s;

TEST(Http2Guard, RapidResetIsCutAfterTheResetBurstWhateverThePieces) {
  Http2Limits limits;
  std::string attack(http2::kPreface);
  attack += frame(0x4, 0, 0, 0);  // SETTINGS
  // HEADERS then RST_STREAM on stream after stream, all in one instant:
  // stream opens run out at streamBurst (64), resets at resetBurst (32).
  for (std::uint32_t s = 1; s < 2 * 40; s += 2) attack += headers(s) + reset(s);
  for (std::size_t piece : {std::size_t{1}, std::size_t{7}, std::size_t{9}, std::size_t{4096}}) {
    Http2AddressRates rates(limits);
    Http2Guard g(rates, "10.0.0.1");
    const auto abuse = feedIn(g, attack, piece, t0);
    ASSERT_TRUE(abuse.has_value()) << "piece " << piece;
    EXPECT_EQ(abuse->label, "http2_reset_rate") << "piece " << piece;
    EXPECT_EQ(abuse->code, http2::kEnhanceYourCalm);
    // The 33rd reset is refused: its stream, 65, was the last opened.
    EXPECT_EQ(g.lastStream(), 2u * 33 - 1) << "piece " << piece;
  }
}

TEST(Http2Guard, ResetsAtTheRefillRatePassForAsLongAsTheyCome) {
  Http2AddressRates rates(Http2Limits{});
  Http2Guard g(rates, "10.0.0.1");
  ASSERT_FALSE(g.feed(bytesOf(std::string(http2::kPreface)), t0));
  // 3 streams opened and reset a second (under 4 resets a second and 16
  // opens) for ten minutes: never cut.
  std::uint32_t s = 1;
  for (int second = 0; second < 600; ++second) {
    for (int i = 0; i < 3; ++i, s += 2) {
      ASSERT_FALSE(g.feed(bytesOf(headers(s) + reset(s)), t0 + std::chrono::seconds(second))) << "second " << second;
    }
  }
}

TEST(Http2Guard, StreamsOpenedTooFastAreCutEvenWithoutResets) {
  Http2AddressRates rates(Http2Limits{});
  Http2Guard g(rates, "10.0.0.1");
  std::string bytes(http2::kPreface);
  for (std::uint32_t s = 1; s <= 2 * 64 - 1; s += 2) bytes += headers(s);
  ASSERT_FALSE(g.feed(bytesOf(bytes), t0)) << "64 streams at once are the burst";
  const auto abuse = g.feed(bytesOf(headers(129)), t0);
  ASSERT_TRUE(abuse.has_value());
  EXPECT_EQ(abuse->label, "http2_stream_rate");
  // A HEADERS frame on a stream already open (trailers) opens nothing.
  Http2AddressRates rates2(Http2Limits{});
  Http2Guard g2(rates2, "10.0.0.1");
  std::string trailers(http2::kPreface);
  trailers += headers(1);
  for (int i = 0; i < 500; ++i) trailers += headers(1);
  EXPECT_FALSE(g2.feed(bytesOf(trailers), t0));
}

TEST(Http2Guard, AnAddressSharesItsRatesAcrossItsConnections) {
  Http2AddressRates rates(Http2Limits{});
  // 8 connections from one address, each under its own reset burst (32):
  // together past the address's 128.
  std::vector<std::unique_ptr<Http2Guard>> guards;
  std::optional<Http2Abuse> abuse;
  int connection = 0;
  for (; connection < 8 && !abuse; ++connection) {
    guards.push_back(std::make_unique<Http2Guard>(rates, "10.0.0.1"));
    std::string bytes(http2::kPreface);
    for (std::uint32_t s = 1; s < 2 * 20; s += 2) bytes += headers(s) + reset(s);
    abuse = guards.back()->feed(bytesOf(bytes), t0);
  }
  ASSERT_TRUE(abuse.has_value());
  EXPECT_NE(abuse->reason.find("from 10.0.0.1"), std::string::npos) << abuse->reason;
  EXPECT_EQ(connection, 7) << "128 address resets at 20 a connection run out in the 7th";
  // Another address has rates of its own.
  Http2Guard other(rates, "10.0.0.2");
  std::string bytes(http2::kPreface);
  for (std::uint32_t s = 1; s < 2 * 20; s += 2) bytes += headers(s) + reset(s);
  EXPECT_FALSE(other.feed(bytesOf(bytes), t0));
}

TEST(Http2Guard, AHeaderBlockThatNeverEndsIsCut) {
  Http2AddressRates rates(Http2Limits{});
  Http2Guard g(rates, "10.0.0.1");
  std::string bytes(http2::kPreface);
  bytes += frame(http2::kHeaders, 0, 1, 1000);  // no END_HEADERS: CONTINUATION follows
  ASSERT_FALSE(g.feed(bytesOf(bytes), t0));
  std::optional<Http2Abuse> abuse;
  int frames = 0;
  while (!abuse && frames < 1000) {
    abuse = g.feed(bytesOf(frame(http2::kContinuation, 0, 1, 1000)), t0);
    ++frames;
  }
  ASSERT_TRUE(abuse.has_value());
  EXPECT_EQ(abuse->label, "http2_header_block");
  EXPECT_EQ(frames, 65) << "1,000 + 65 × 1,000 bytes is the first block over 64 KiB";
  // Ended blocks of any number count one by one.
  Http2AddressRates rates2(Http2Limits{});
  Http2Guard g2(rates2, "10.0.0.1");
  std::string ok(http2::kPreface);
  ok += frame(http2::kHeaders, 0, 1, 60000) + frame(http2::kContinuation, http2::kEndHeaders, 1, 5000);
  for (int i = 0; i < 10; ++i) ok += frame(http2::kHeaders, http2::kEndHeaders, 1, 60000);
  EXPECT_FALSE(g2.feed(bytesOf(ok), t0));
}

TEST(Http2Guard, BytesThatAreNotHttp2AreCutAtOnce) {
  Http2AddressRates rates(Http2Limits{});
  Http2Guard g(rates, "10.0.0.1");
  const auto abuse = g.feed(bytesOf("GET / HTTP/1.1\r\nHost: x\r\n\r\n"), t0);
  ASSERT_TRUE(abuse.has_value());
  EXPECT_EQ(abuse->label, "http2_preface");
  EXPECT_EQ(abuse->code, http2::kProtocolError);
  // A preface split anywhere is a preface.
  Http2Guard g2(rates, "10.0.0.1");
  const std::string preface(http2::kPreface);
  for (char c : preface) ASSERT_FALSE(g2.feed(bytesOf(std::string(1, c)), t0));
  EXPECT_TRUE(g2.prefaceDone());
}

TEST(Http2AddressRates, APenaltyLastsItsSecondsAndAFullTableForgetsAnIdleAddress) {
  Http2Limits limits;
  limits.maxAddresses = 3;
  Http2AddressRates rates(limits);
  rates.penalize("a", t0);
  EXPECT_NEAR(rates.penaltyLeft("a", t0 + 4s), 6.0, 1e-6);
  EXPECT_EQ(rates.penaltyLeft("a", t0 + 10s), 0.0);
  rates.connected("b", t0 + 1s);
  rates.connected("c", t0 + 2s);
  rates.connected("d", t0 + 3s);  // full: "a" (no connection, oldest) goes
  EXPECT_EQ(rates.size(), 3u);
  EXPECT_EQ(rates.penaltyLeft("a", t0 + 4s), 0.0);
  rates.connected("e", t0 + 4s);  // every one connected: the table grows
  EXPECT_EQ(rates.size(), 4u);
  rates.disconnected("b");
  rates.connected("f", t0 + 5s);  // "b" has none now and goes
  EXPECT_EQ(rates.size(), 4u);
}

TEST(Http2FrameReader, StopsAtTheEndOfTheFrameUnderWay) {
  Http2FrameReader r;
  const std::string two = frame(0x0, 0, 1, 100) + frame(0x0, 0, 1, 50);
  int frames = 0;
  auto count = [&](const Http2FrameHeader&) { ++frames; };
  // Half of the first frame, then "to the boundary" takes the rest of it only.
  EXPECT_EQ(r.read(bytesOf(two.substr(0, 60)), count), 60u);
  EXPECT_FALSE(r.atBoundary());
  EXPECT_EQ(r.read(bytesOf(two.substr(60)), count, true), 109u - 60u);
  EXPECT_TRUE(r.atBoundary());
  EXPECT_EQ(r.read(bytesOf(two.substr(109)), count, true), 0u);
  EXPECT_EQ(frames, 1);
}

TEST(Http2Goaway, IsTheFrameOfRfc9113Section6_8) {
  const std::string f = http2Goaway(0x80000005u, http2::kEnhanceYourCalm, "calm");
  const std::string expected("\x00\x00\x0c\x07\x00\x00\x00\x00\x00"  // length 12, GOAWAY, stream 0
                             "\x00\x00\x00\x05"                      // last stream 5 (reserved bit cleared)
                             "\x00\x00\x00\x0b"                      // ENHANCE_YOUR_CALM
                             "calm",
                             21);
  EXPECT_EQ(f, expected);
}

}  // namespace
}  // namespace haarcast::net

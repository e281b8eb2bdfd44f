#pragma once
// The `openigtlink://HOST:PORT` device: a haptic device on another computer, reached through a
// bridge that speaks OpenIGTLink (protocol version 1 messages, libOpenIGTLink 1.11) over TCP.
// tubeplan is the client. In: the device's pose as TRANSFORM messages (translation in mm, the
// OpenIGTLink convention; the bridge's frame is taken as the world frame). Out: the limited wrench
// as two SENSOR messages sent together, "tubeplan_force" (3 values, N) and "tubeplan_torque"
// (3 values, N m): a TRANSFORM cannot carry a wrench, and a SENSOR message has one unit for all
// its values, so a single 6-value message could not say that three are newtons and three newton
// metres. Each wrench's header timestamp echoes the timestamp of the TRANSFORM it was computed
// from, so the bridge can measure the round trip on its own clock (docs/live.md).
//
// Threads: a receiver thread reads the socket and publishes the newest pose through a seqlock;
// Read (the servo thread) takes it with one attempt and never blocks or allocates. SendWrench
// (the servo thread) packs into a buffer made at Open and sends without blocking
// (MSG_DONTWAIT): a bridge that stops reading makes wrenches be skipped and counted, never the
// servo wait. The socket is plain POSIX and libOpenIGTLink packs and checks the messages: its
// igtl::ClientSocket connects without a timeout and its Send loops until the whole message is
// written, which would let a stalled bridge hold the 1 kHz loop.

#include <atomic>
#include <cstdint>
#include <mutex>
#include <string>
#include <thread>

#include <tubeplan/device/device.hpp>
#include <tubeplan/device/handoff.hpp>

namespace tubeplan::device {

struct OpenIGTLinkOptions {
  std::string host = "127.0.0.1";
  int port = 18944;  ///< OpenIGTLink's registered port
  /// Connecting and the first TRANSFORM must both happen within this time.
  double connect_timeout_s = 2.0;
  /// The bridge reports no limits (OpenIGTLink has no message for them): they are these,
  /// by default the PHANToM Premium 1.5/6DOF's as the emulator's, overridden by `--device`
  /// arguments; the scene's device block limits them further (LimitsFor).
  DeviceSpec spec = PhantomPremium15Spec();
  /// Poses older than this are stale data (live turns it into ServoConfig::max_stale_ticks): a
  /// bridge sends at about the servo's rate, but a network adds jitter that one tick would not
  /// survive.
  double stale_after_s = 0.02;
};

/// What went over the link, for tests and the end-of-session note. Read after Close.
struct OpenIGTLinkCounters {
  std::uint64_t poses = 0;             ///< TRANSFORM messages received
  std::uint64_t other_messages = 0;    ///< messages of other types, skipped
  std::uint64_t wrenches_sent = 0;     ///< wrench pairs written in full to the socket
  std::uint64_t wrenches_skipped = 0;  ///< not sent: the socket's buffer was full
};

class OpenIGTLinkDevice final : public HapticDevice {
 public:
  explicit OpenIGTLinkDevice(OpenIGTLinkOptions options);
  ~OpenIGTLinkDevice() override;

  /// Connects (within the timeout), starts the receiver and waits for the first pose.
  std::string Open() override;
  std::string Calibrate() override { return {}; }
  const DeviceSpec& spec() const override { return options_.spec; }
  /// The newest pose; false once the link has failed (closed by the bridge, a bad message).
  bool Read(DeviceSample& sample) override;
  /// Sends zero (waiting up to 100 ms for room), half-closes the link and reads until the bridge
  /// closes its end (up to 0.5 s, so the link ends without a reset), then disconnects.
  void Close() override;

  /// Why the link failed, empty while it is up. Safe from any thread after Read returned false.
  std::string link_error() const;
  OpenIGTLinkCounters counters() const;
  const OpenIGTLinkOptions& options() const { return options_; }

  /// The newest pose as the receiver publishes it: plain words for the seqlock.
  struct Pose {
    std::uint64_t sequence = 0;
    std::uint64_t igtl_timestamp = 0;  ///< the TRANSFORM's, echoed in the wrench
    double p_W_m[3] = {};
    double q_W_wxyz[4] = {1, 0, 0, 0};
    double v_W_m_per_s[3] = {};
    double w_W_rad_per_s[3] = {};
  };

 protected:
  void SendWrench(const Eigen::Vector3d& force_W_N, const Eigen::Vector3d& torque_W_Nm) override;

 private:
  void Receive();
  void FailLink(const std::string& why);
  bool SendPending(int flags);

  OpenIGTLinkOptions options_;
  int fd_ = -1;
  std::thread receiver_;
  std::atomic<bool> stopping_{false};
  std::atomic<bool> closing_{false};        // Close half-closed the link: the bridge's end is due
  std::atomic<bool> receiver_done_{false};  // the receiver thread has returned
  std::atomic<bool> link_failed_{false};
  mutable std::mutex error_mutex_;  // the receiver's error text (cold path only)
  std::string link_error_;
  Seqlock<Pose> pose_;
  Pose last_{};  // the servo thread's last pose, handed back when a read overlaps a write

  // Out (the servo thread, then Close): two SENSOR messages packed at Open, values rewritten.
  static constexpr std::size_t kSensorMessageBytes = 58 + 10 + 3 * 8;
  unsigned char out_[2 * kSensorMessageBytes] = {};
  std::size_t out_pending_ = 0;  // bytes of out_ not yet written (a partial send)
  std::size_t out_offset_ = 0;
  std::uint64_t unit_N_ = 0, unit_Nm_ = 0;  // OpenIGTLink's packed units of the two messages

  std::atomic<std::uint64_t> poses_{0}, other_messages_{0};
  std::uint64_t wrenches_sent_ = 0, wrenches_skipped_ = 0;
};

}  // namespace tubeplan::device

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <ctime>
#include <fcntl.h>
#include <igtlMessageHeader.h>
#include <igtlTransformMessage.h>
#include <igtl_header.h>
#include <igtl_sensor.h>
#include <igtl_transform.h>
#include <igtl_unit.h>
#include <igtl_util.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <tubeplan/device/openigtlink.hpp>

namespace tubeplan::device {
namespace {

static_assert(sizeof(igtl_header) == IGTL_HEADER_SIZE);
static_assert(sizeof(igtl_sensor_header) == IGTL_SENSOR_HEADER_SIZE);

// A body larger than this is not a message a haptic bridge sends: the link is out of step.
constexpr std::uint64_t kMaxBodyBytes = 1u << 24;

std::int64_t MonotonicNs() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return std::int64_t(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

// OpenIGTLink's timestamp: seconds in the high 32 bits, a binary fraction in the low 32.
std::int64_t TimestampNs(std::uint64_t stamp) {
  const auto seconds = std::int64_t(stamp >> 32);
  const auto fraction = double(stamp & 0xffffffffu) / 4294967296.0;
  return seconds * 1'000'000'000 + std::llround(fraction * 1e9);
}

igtl_unit UnitOf(int base, bool times_metre) {
  igtl_unit_data data;
  igtl_unit_init(&data);
  data.prefix = IGTL_UNIT_PREFIX_NONE;
  data.unit[0] = static_cast<igtl_uint8>(base);
  data.exp[0] = 1;
  if (times_metre) {
    data.unit[1] = IGTL_UNIT_SI_BASE_METER;
    data.exp[1] = 1;
  }
  return igtl_unit_pack(&data);
}

// A fixed-width name field of the header: NUL-padded, not NUL-terminated when full.
void CopyName(char* to, std::size_t size, const char* from) {
  std::memset(to, 0, size);
  std::memcpy(to, from, std::min(size, std::strlen(from)));
}

// One SENSOR message of three values at `at` (kSensorMessageBytes), in network byte order with
// its CRC: only C calls of libOpenIGTLink, on the stack, so the servo thread allocates nothing.
void PackSensor(unsigned char* at, const char* device_name, igtl_unit unit, std::uint64_t stamp,
                const Eigen::Vector3d& values) {
  igtl_sensor_header body_header{};
  body_header.larray = 3;
  body_header.status = 0;
  body_header.unit = unit;
  igtl_float64 data[3] = {values.x(), values.y(), values.z()};
  igtl_sensor_convert_byte_order(&body_header, data);
  igtl_header header{};
  header.version = IGTL_HEADER_VERSION;
  CopyName(header.name, IGTL_HEADER_TYPE_SIZE, "SENSOR");
  CopyName(header.device_name, IGTL_HEADER_NAME_SIZE, device_name);
  header.timestamp = stamp;
  header.body_size = IGTL_SENSOR_HEADER_SIZE + sizeof(data);
  header.crc = igtl_sensor_get_crc(&body_header, data);
  igtl_header_convert_byte_order(&header);
  std::memcpy(at, &header, IGTL_HEADER_SIZE);
  std::memcpy(at + IGTL_HEADER_SIZE, &body_header, IGTL_SENSOR_HEADER_SIZE);
  std::memcpy(at + IGTL_HEADER_SIZE + IGTL_SENSOR_HEADER_SIZE, data, sizeof(data));
}

std::string Where(const OpenIGTLinkOptions& o) { return o.host + ":" + std::to_string(o.port); }

std::string SecondsText(double s) {
  char text[32];
  std::snprintf(text, sizeof text, "%g s", s);
  return text;
}

// A non-blocking connection to host:port within the timeout; -1 and `error` on failure.
int Connect(const OpenIGTLinkOptions& o, std::string& error) {
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* found = nullptr;
  const std::string port = std::to_string(o.port);
  if (const int e = getaddrinfo(o.host.c_str(), port.c_str(), &hints, &found); e != 0) {
    error = "cannot resolve \"" + o.host + "\": " + gai_strerror(e);
    return -1;
  }
  const auto deadline = std::chrono::steady_clock::now() +
                        std::chrono::microseconds(std::llround(o.connect_timeout_s * 1e6));
  int fd = -1;
  for (addrinfo* a = found; a != nullptr && fd < 0; a = a->ai_next) {
    fd = socket(a->ai_family, a->ai_socktype | SOCK_NONBLOCK | SOCK_CLOEXEC, a->ai_protocol);
    if (fd < 0) {
      error = std::string("socket: ") + std::strerror(errno);
      continue;
    }
    int e = connect(fd, a->ai_addr, a->ai_addrlen) == 0 ? 0 : errno;
    if (e == EINPROGRESS) {
      pollfd p{fd, POLLOUT, 0};
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
          deadline - std::chrono::steady_clock::now());
      const int ready = poll(&p, 1, int(std::max<std::int64_t>(0, left.count())));
      if (ready == 0) {
        e = ETIMEDOUT;
      } else {
        socklen_t length = sizeof e;
        if (getsockopt(fd, SOL_SOCKET, SO_ERROR, &e, &length) != 0) e = errno;
      }
    }
    if (e == 0) break;
    if (e == ECONNREFUSED)
      error = "connection refused by " + Where(o) +
              " (no OpenIGTLink bridge is listening there: start it, or check the port)";
    else if (e == ETIMEDOUT)
      error = "no answer from " + Where(o) + " within " + SecondsText(o.connect_timeout_s) +
              " (is the address right, and the bridge's computer reachable?)";
    else
      error = "cannot connect to " + Where(o) + ": " + std::strerror(e);
    close(fd);
    fd = -1;
  }
  freeaddrinfo(found);
  if (fd < 0) return -1;
  // Small messages, one per tick each way: Nagle's algorithm would hold them back.
  const int one = 1;
  setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
  error.clear();
  return fd;
}

}  // namespace

OpenIGTLinkDevice::OpenIGTLinkDevice(OpenIGTLinkOptions options)
    : options_(std::move(options)),
      unit_N_(UnitOf(IGTL_UNIT_SI_DERIVED_NEWTON, false)),
      unit_Nm_(UnitOf(IGTL_UNIT_SI_DERIVED_NEWTON, true)) {
  options_.spec.name += " over OpenIGTLink " + Where(options_);
}

OpenIGTLinkDevice::~OpenIGTLinkDevice() { Close(); }

std::string OpenIGTLinkDevice::link_error() const {
  std::lock_guard<std::mutex> lock(error_mutex_);
  return link_error_;
}

OpenIGTLinkCounters OpenIGTLinkDevice::counters() const {
  return {poses_.load(std::memory_order_relaxed), other_messages_.load(std::memory_order_relaxed),
          wrenches_sent_, wrenches_skipped_};
}

void OpenIGTLinkDevice::FailLink(const std::string& why) {
  {
    std::lock_guard<std::mutex> lock(error_mutex_);
    if (link_error_.empty()) link_error_ = why;
  }
  link_failed_.store(true, std::memory_order_release);
}

std::string OpenIGTLinkDevice::Open() {
  if (fd_ >= 0) return {};
  std::string error;
  fd_ = Connect(options_, error);
  if (fd_ < 0) return error;
  stopping_.store(false);
  closing_.store(false);
  receiver_done_.store(false);
  link_failed_.store(false);
  link_error_.clear();
  out_pending_ = 0;
  receiver_ = std::thread([this] {
    Receive();
    receiver_done_.store(true, std::memory_order_release);
  });
  // The servo's first tick needs a pose: wait for it here, where waiting is allowed.
  const auto deadline = std::chrono::steady_clock::now() +
                        std::chrono::microseconds(std::llround(options_.connect_timeout_s * 1e6));
  Pose first;
  while (!pose_.TryLoad(first)) {
    if (link_failed_.load(std::memory_order_acquire)) {
      error = "the link to " + Where(options_) + " failed before the first pose: " + link_error();
      break;
    }
    if (std::chrono::steady_clock::now() > deadline) {
      error = "connected to " + Where(options_) + " but no TRANSFORM arrived within " +
              SecondsText(options_.connect_timeout_s) + " (is the bridge streaming the pose?)";
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  if (!error.empty()) {
    Close();
    return error;
  }
  last_ = first;
  return {};
}

// The receiver thread: whole messages off the socket; TRANSFORMs become the newest pose, other
// types are skipped. Any failure (closed, a bad CRC, a message out of step) ends the link: the
// servo's next Read reports a device error and the force goes to zero.
void OpenIGTLinkDevice::Receive() {
  // Reads exactly n bytes; false when stopping or the link failed (then FailLink was called
  // unless stopping).
  auto read_fully = [this](void* to, std::size_t n) {
    auto* bytes = static_cast<unsigned char*>(to);
    std::size_t got = 0;
    while (got < n) {
      if (stopping_.load(std::memory_order_acquire)) return false;
      pollfd p{fd_, POLLIN, 0};
      // A bounded wait, so that Close is seen even if shutdown() did not wake the poll.
      if (poll(&p, 1, 50) <= 0) continue;
      const ssize_t r = recv(fd_, bytes + got, n - got, 0);
      if (r > 0) {
        got += std::size_t(r);
      } else if (r == 0) {
        if (!stopping_.load() && !closing_.load()) FailLink("the bridge closed the connection");
        return false;
      } else if (errno == ECONNRESET) {
        // A peer that closes with our wrenches still unread in its buffer resets the connection
        // instead of ending it (RFC 1122, 4.2.2.13): the same hang-up, seen as an error.
        if (!stopping_.load() && !closing_.load())
          FailLink("the bridge closed the connection (reset: it closed with our data unread)");
        return false;
      } else if (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR) {
        if (!stopping_.load()) FailLink(std::string("receiving: ") + std::strerror(errno));
        return false;
      }
    }
    return true;
  };

  igtl::MessageHeader::Pointer header = igtl::MessageHeader::New();
  igtl::TransformMessage::Pointer transform = igtl::TransformMessage::New();
  unsigned char skip[4096];
  Pose pose;
  std::int64_t previous_ns = 0;
  Eigen::Vector3d previous_p = Eigen::Vector3d::Zero();
  Eigen::Quaterniond previous_q = Eigen::Quaterniond::Identity();
  bool have_previous = false;
  for (;;) {
    header->InitPack();
    if (!read_fully(header->GetPackPointer(), std::size_t(header->GetPackSize()))) return;
    igtl_header raw;
    std::memcpy(&raw, header->GetPackPointer(), IGTL_HEADER_SIZE);
    igtl_header_convert_byte_order(&raw);
    if (raw.body_size > kMaxBodyBytes) {
      FailLink("a message announced a body of " + std::to_string(raw.body_size) +
               " bytes: the link is out of step or not OpenIGTLink");
      return;
    }
    header->Unpack();
    if (std::strncmp(raw.name, "TRANSFORM", IGTL_HEADER_TYPE_SIZE) != 0) {
      for (std::uint64_t left = raw.body_size; left > 0;) {
        const std::size_t n = std::size_t(std::min<std::uint64_t>(left, sizeof skip));
        if (!read_fully(skip, n)) return;
        left -= n;
      }
      other_messages_.fetch_add(1, std::memory_order_relaxed);
      continue;
    }
    if (raw.body_size != IGTL_TRANSFORM_SIZE) {
      FailLink("a TRANSFORM of " + std::to_string(raw.body_size) + " bytes (expected " +
               std::to_string(IGTL_TRANSFORM_SIZE) + ")");
      return;
    }
    transform->SetMessageHeader(header);
    transform->AllocatePack();
    if (!read_fully(transform->GetPackBodyPointer(), std::size_t(transform->GetPackBodySize())))
      return;
    if (!(transform->Unpack(1) & igtl::MessageHeader::UNPACK_BODY)) {
      FailLink("a TRANSFORM failed its CRC check");
      return;
    }
    igtl::Matrix4x4 m;
    transform->GetMatrix(m);
    Eigen::Matrix3d R;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) R(i, j) = double(m[i][j]);
    // float32 on the wire: a rotation orthonormal to 1e-7 only; the quaternion makes it exact.
    const Eigen::Quaterniond q = Eigen::Quaterniond(R).normalized();
    const Eigen::Vector3d p = 1e-3 * Eigen::Vector3d(double(m[0][3]), double(m[1][3]),
                                                     double(m[2][3]));  // mm on the wire
    // Velocity by a finite difference on the bridge's own timestamps (TRANSFORM has none);
    // the arrival time when the bridge sends no timestamp. A gap of more than 100 ms (or time
    // going back) is a restart, not motion.
    const std::int64_t t_ns = raw.timestamp != 0 ? TimestampNs(raw.timestamp) : MonotonicNs();
    Eigen::Vector3d v = Eigen::Vector3d::Zero(), w = Eigen::Vector3d::Zero();
    const double dt_s = double(t_ns - previous_ns) * 1e-9;
    if (have_previous && dt_s > 0.0 && dt_s <= 0.1) {
      v = (p - previous_p) / dt_s;
      Eigen::Quaterniond dq = q * previous_q.conjugate();
      if (dq.w() < 0.0) dq.coeffs() *= -1.0;  // the shorter way round
      const Eigen::AngleAxisd turn(dq);
      w = turn.axis() * (turn.angle() / dt_s);
    }
    have_previous = true;
    previous_ns = t_ns;
    previous_p = p;
    previous_q = q;

    pose.sequence += 1;
    pose.igtl_timestamp = raw.timestamp;
    for (int i = 0; i < 3; ++i) {
      pose.p_W_m[i] = p[i];
      pose.v_W_m_per_s[i] = v[i];
      pose.w_W_rad_per_s[i] = w[i];
    }
    pose.q_W_wxyz[0] = q.w();
    pose.q_W_wxyz[1] = q.x();
    pose.q_W_wxyz[2] = q.y();
    pose.q_W_wxyz[3] = q.z();
    pose_.Store(pose);
    poses_.fetch_add(1, std::memory_order_relaxed);
  }
}

bool OpenIGTLinkDevice::Read(DeviceSample& sample) {
  if (fd_ < 0 || link_failed_.load(std::memory_order_acquire)) return false;
  // One attempt: when the receiver is writing just now, the last pose again (its sequence
  // unchanged: one stale tick, which the servo tolerates up to its stale window).
  Pose p;
  if (pose_.TryLoad(p)) last_ = p;
  sample.sequence = last_.sequence;
  const Eigen::Quaterniond q(last_.q_W_wxyz[0], last_.q_W_wxyz[1], last_.q_W_wxyz[2],
                             last_.q_W_wxyz[3]);
  sample.X_W_hand.linear() = q.toRotationMatrix();
  sample.X_W_hand.translation() = Eigen::Vector3d(last_.p_W_m[0], last_.p_W_m[1], last_.p_W_m[2]);
  sample.v_W_m_per_s =
      Eigen::Vector3d(last_.v_W_m_per_s[0], last_.v_W_m_per_s[1], last_.v_W_m_per_s[2]);
  sample.w_W_rad_per_s =
      Eigen::Vector3d(last_.w_W_rad_per_s[0], last_.w_W_rad_per_s[1], last_.w_W_rad_per_s[2]);
  sample.buttons = 0;  // TRANSFORM carries no buttons
  return true;
}

// Writes what is left of out_; true when all of it went out. MSG_NOSIGNAL: a closed link is an
// error return, not a SIGPIPE.
bool OpenIGTLinkDevice::SendPending(int flags) {
  while (out_pending_ > 0) {
    const ssize_t n = send(fd_, out_ + out_offset_, out_pending_, flags | MSG_NOSIGNAL);
    if (n <= 0) return false;  // full (EAGAIN) or failed: the receiver reports a dead link
    out_offset_ += std::size_t(n);
    out_pending_ -= std::size_t(n);
  }
  return true;
}

void OpenIGTLinkDevice::SendWrench(const Eigen::Vector3d& force_W_N,
                                   const Eigen::Vector3d& torque_W_Nm) {
  if (fd_ < 0 || link_failed_.load(std::memory_order_acquire)) return;
  // A wrench half written on an earlier tick goes out first (the stream must stay in step);
  // while the socket is full the new wrench is skipped: only the newest matters, and the next
  // tick brings one.
  if (out_pending_ > 0 && !SendPending(MSG_DONTWAIT)) {
    ++wrenches_skipped_;
    return;
  }
  PackSensor(out_, "tubeplan_force", unit_N_, last_.igtl_timestamp, force_W_N);
  PackSensor(out_ + kSensorMessageBytes, "tubeplan_torque", unit_Nm_, last_.igtl_timestamp,
             torque_W_Nm);
  out_offset_ = 0;
  out_pending_ = sizeof out_;
  if (SendPending(MSG_DONTWAIT)) ++wrenches_sent_;
}

void OpenIGTLinkDevice::Close() {
  if (fd_ < 0) return;
  if (receiver_.joinable() && !link_failed_.load(std::memory_order_acquire)) {
    // Zero must be the last wrench the bridge gets: finish a partial one, then send zero,
    // waiting up to 100 ms for room (a bridge that reads nothing must zero on its own
    // watchdog, docs/live.md).
    const std::int64_t give_up_ns = MonotonicNs() + 100'000'000;
    auto flush = [&] {
      while (!SendPending(MSG_DONTWAIT)) {
        const std::int64_t left_ns = give_up_ns - MonotonicNs();
        if (left_ns <= 0) return false;
        pollfd p{fd_, POLLOUT, 0};
        if (poll(&p, 1, int(left_ns / 1'000'000) + 1) < 0 && errno != EINTR) return false;
        if (p.revents & (POLLERR | POLLHUP)) return false;
      }
      return true;
    };
    if (flush()) {
      Disable();
      flush();
    }
    // An orderly end: FIN after the zero, and the bridge's poses read until it closes its end
    // (up to 0.5 s). Closing with poses unread, or with more arriving, resets the connection,
    // and a bridge that meets the reset on a send loses the wrenches it had not read yet.
    if (poses_.load(std::memory_order_relaxed) > 0) {
      closing_.store(true, std::memory_order_release);
      shutdown(fd_, SHUT_WR);
      const std::int64_t end_due_ns = MonotonicNs() + 500'000'000;
      while (!receiver_done_.load(std::memory_order_acquire) && MonotonicNs() < end_due_ns)
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  }
  stopping_.store(true, std::memory_order_release);
  shutdown(fd_, SHUT_RDWR);
  if (receiver_.joinable()) receiver_.join();
  close(fd_);
  fd_ = -1;
}

}  // namespace tubeplan::device

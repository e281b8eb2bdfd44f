// igtl-bridge: an emulated OpenIGTLink haptic bridge, the other end of `tubeplan live --device
// openigtlink://HOST:PORT` (docs/live.md). It listens (127.0.0.1 by default), takes one client,
// streams the poses of a trajectory CSV (the repository's trajectory format) as TRANSFORM
// messages at a fixed rate on absolute deadlines, and reads the wrenches back (SENSOR messages
// "tubeplan_force" in N and "tubeplan_torque" in N m), recording them and the round trip from
// each pose's sample time to the wrench computed from it (the wrench echoes the pose's
// timestamp).
//
// It packs and unpacks with libOpenIGTLink's C++ message classes, while tubeplan's device packs
// its wrenches with the library's C calls: the tests thus check the two against each other (the
// CRC of every wrench is checked here).
//
// Faults for the tests: --stop-after S stops the poses (the link stays up: stale data),
// --close-after S closes the connection, --drop P loses each pose with probability P (a
// function of --seed N and the pose's index, so a run drops the same poses again), and
// --delay-ms D with --delay-every K holds back the poses sampled in the D ms from pose K, 2K, ...
// on and sends them with the next one, at once (a burst: the first arrives D ms late, and the
// client sees no new pose for D ms). A pose dropped or held keeps its sample time and its place
// in the trajectory; the summary line counts the poses sent, dropped, delayed and the pauses.
#include <algorithm>
#include <arpa/inet.h>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <fstream>
#include <igtlMessageHeader.h>
#include <igtlSensorMessage.h>
#include <igtlTransformMessage.h>
#include <igtl_header.h>
#include <igtl_util.h>
#include <iostream>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <string>
#include <sys/socket.h>
#include <unistd.h>
#include <vector>

#include <CLI/CLI.hpp>

#include <tubeplan/io/trajectory_csv.hpp>
#include <tubeplan/trajectories/trajectory.hpp>

namespace {

std::atomic<int> g_signal{0};
extern "C" void OnSignal(int s) { g_signal.store(s); }

std::int64_t NowNs(clockid_t clock) {
  timespec ts{};
  clock_gettime(clock, &ts);
  return std::int64_t(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

// The wall clock in OpenIGTLink's timestamp form (the protocol's timestamps are UTC).
void SplitNs(std::int64_t ns, unsigned& seconds, unsigned& fraction) {
  seconds = unsigned(ns / 1'000'000'000);
  fraction = igtl_nanosec_to_frac(igtl_uint32(ns % 1'000'000'000));
}

bool SendAll(int fd, const void* data, std::size_t n) {
  const auto* bytes = static_cast<const unsigned char*>(data);
  while (n > 0) {
    const ssize_t sent = send(fd, bytes, n, MSG_NOSIGNAL);
    if (sent < 0 && errno == EINTR) continue;
    if (sent <= 0) return false;
    bytes += sent;
    n -= std::size_t(sent);
  }
  return true;
}

struct Options {
  std::string trajectory;
  std::string bind = "127.0.0.1";
  int port = 18944;
  double rate_hz = 1000.0;
  double stop_after_s = 0.0;   // 0: never
  double close_after_s = 0.0;  // 0: never
  double drop_probability = 0.0;
  std::uint64_t seed = 1;
  double delay_ms = 0.0;  // 0: no pauses
  long delay_every = 1000;
  double accept_timeout_s = 30.0;
  double max_time_s = 600.0;
  std::string wrenches;
};

struct Wrench {
  double t_s;  // since the first pose
  bool force;  // else torque
  double x, y, z;
  double round_trip_us;  // -1 when the wrench echoed no timestamp
};

// A uniform number in [0, 1) that depends only on the seed and the pose's index (splitmix64).
double Uniform(std::uint64_t seed, std::uint64_t index) {
  std::uint64_t z = seed + (index + 1) * 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  z ^= z >> 31;
  return double(z >> 11) * 0x1.0p-53;
}

double Percentile(std::vector<double> values, double fraction) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const auto rank = std::size_t(std::ceil(fraction * double(values.size())));
  return values[std::min(values.size() - 1, rank == 0 ? 0 : rank - 1)];
}

// A socket listening on --bind:--port, its port said on stdout's first line; -1 after saying why.
int Listen(const Options& o) {
  const int listener = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  const int one = 1;
  setsockopt(listener, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(std::uint16_t(o.port));
  if (inet_pton(AF_INET, o.bind.c_str(), &address.sin_addr) != 1) {
    std::cerr << "igtl-bridge: error: --bind \"" << o.bind << "\" is not an IPv4 address\n";
    return -1;
  }
  if (bind(listener, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0 ||
      listen(listener, 1) != 0) {
    std::cerr << "igtl-bridge: error: cannot listen on " << o.bind << ":" << o.port << ": "
              << std::strerror(errno) << "\n";
    return -1;
  }
  socklen_t length = sizeof address;
  getsockname(listener, reinterpret_cast<sockaddr*>(&address), &length);
  // The first line of stdout: the port (a test asks for port 0 and reads which it got).
  std::cout << "igtl-bridge: listening on " << o.bind << ":" << ntohs(address.sin_port)
            << std::endl;
  return listener;
}

// The one client, within --accept-timeout, sent to without Nagle's delay; -1 after saying why.
int AcceptOne(const Options& o, int listener) {
  pollfd wait{listener, POLLIN, 0};
  if (poll(&wait, 1, int(o.accept_timeout_s * 1000)) <= 0) {
    std::cerr << "igtl-bridge: error: no client within " << o.accept_timeout_s << " s\n";
    return -1;
  }
  const int fd = accept4(listener, nullptr, nullptr, SOCK_CLOEXEC);
  close(listener);
  if (fd < 0) {
    std::cerr << "igtl-bridge: error: accept: " << std::strerror(errno) << "\n";
    return -1;
  }
  const int one = 1;
  setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
  return fd;
}

// The link's state: the messages reused, the bytes waiting, what was sent and received.
struct Link {
  int fd = -1;
  igtl::TransformMessage::Pointer transform = igtl::TransformMessage::New();
  igtl::MessageHeader::Pointer header = igtl::MessageHeader::New();
  igtl::SensorMessage::Pointer sensor = igtl::SensorMessage::New();
  std::vector<unsigned char> in;    // received, not yet a whole message
  std::vector<unsigned char> held;  // poses held back in a pause
  std::vector<Wrench> wrenches;
  long poses = 0, bad_crc = 0, other = 0;
  // Poses sampled (the trajectory's index), dropped, held back in a pause, pauses begun.
  long samples = 0, dropped = 0, delayed = 0, pauses = 0;
  std::int64_t start_ns = 0, start_realtime_ns = 0;  // the first pose's clocks
};

// Packs pose `s` into the link's TRANSFORM message, stamped `stamp_ns` (wall clock).
void PackPose(Link& link, const tubeplan::trajectories::HandSample& s, std::int64_t stamp_ns) {
  igtl::Matrix4x4 m;
  const Eigen::Matrix3d R = s.q_WH.normalized().toRotationMatrix();
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) m[i][j] = float(R(i, j));
    m[i][3] = float(s.p_WH_m[i] * 1e3);  // mm, as OpenIGTLink has it
    m[3][i] = 0.0f;
  }
  m[3][3] = 1.0f;
  link.transform->SetMatrix(m);
  unsigned seconds = 0, fraction = 0;
  SplitNs(stamp_ns, seconds, fraction);
  link.transform->SetTimeStamp(seconds, fraction);
  link.transform->Pack();
}

// Sends the next sample's pose, or drops it, or holds it back in a pause (the faults asked
// for). False, with `ended` said, when the connection fails.
bool SendPose(const Options& o, const tubeplan::trajectories::Trajectory& trajectory, double t0,
              std::size_t& cursor, Link& link, std::string& ended) {
  const std::int64_t period_ns = std::int64_t(std::llround(1e9 / o.rate_hz));
  const long hold_count = std::lround(o.delay_ms * 1e-3 * o.rate_hz);
  // The pose of the trajectory at this tick's time; held at its last pose after its end.
  const tubeplan::trajectories::HandSample s =
      tubeplan::trajectories::PoseAt(trajectory, t0 + double(link.samples) / o.rate_hz, cursor);
  // Stamped with its sample time, start + n / rate, as a device stamps its samples: the
  // client's finite-difference velocity then sees the trajectory's, not this process's
  // scheduling; the round trip counts from it, so any lateness of this send is in it.
  PackPose(link, s, link.start_realtime_ns + link.samples * period_ns);
  const auto* packed = static_cast<const unsigned char*>(link.transform->GetPackPointer());
  const auto packed_size = std::size_t(link.transform->GetPackSize());
  // Faults: a pose lost, or held back in a pause and sent with the pose after it.
  const long in_pause = link.samples % o.delay_every;
  const bool hold = hold_count > 0 && link.samples >= o.delay_every && in_pause < hold_count;
  link.pauses += hold && in_pause == 0;
  if (o.drop_probability > 0.0 &&
      Uniform(o.seed, std::uint64_t(link.samples)) < o.drop_probability) {
    ++link.dropped;
  } else if (hold) {
    link.held.insert(link.held.end(), packed, packed + packed_size);
    ++link.delayed;
  } else {
    if (!link.held.empty() && !SendAll(link.fd, link.held.data(), link.held.size())) {
      ended = std::string("sending: ") + std::strerror(errno);
      return false;
    }
    link.poses += long(link.held.size() / packed_size);
    link.held.clear();
    if (!SendAll(link.fd, packed, packed_size)) {
      ended = std::string("sending: ") + std::strerror(errno);
      return false;
    }
    ++link.poses;
  }
  ++link.samples;
  return true;
}

// Unpacks the whole messages in `link.in` (arrived at `arrived_ns`, wall clock), keeping the
// wrenches and counting the others, and leaves the rest of a message for the next bytes.
void TakeMessages(Link& link, std::int64_t arrived_ns) {
  std::vector<unsigned char>& in = link.in;
  std::size_t used = 0;
  while (in.size() - used >= IGTL_HEADER_SIZE) {
    igtl_header raw;
    std::memcpy(&raw, in.data() + used, IGTL_HEADER_SIZE);
    igtl_header_convert_byte_order(&raw);
    if (in.size() - used < IGTL_HEADER_SIZE + raw.body_size) break;
    link.header->InitPack();
    std::memcpy(link.header->GetPackPointer(), in.data() + used, IGTL_HEADER_SIZE);
    link.header->Unpack();
    if (std::strcmp(link.header->GetDeviceType(), "SENSOR") == 0) {
      igtl::SensorMessage::Pointer& sensor = link.sensor;
      sensor->SetMessageHeader(link.header);
      sensor->AllocatePack();
      std::memcpy(sensor->GetPackBodyPointer(), in.data() + used + IGTL_HEADER_SIZE,
                  std::size_t(raw.body_size));
      if (!(sensor->Unpack(1) & igtl::MessageHeader::UNPACK_BODY) || sensor->GetLength() != 3) {
        ++link.bad_crc;
      } else {
        const std::string name = sensor->GetDeviceName();
        unsigned seconds = 0, fraction = 0;
        sensor->GetTimeStamp(&seconds, &fraction);
        const std::int64_t echoed_ns =
            std::int64_t(seconds) * 1'000'000'000 + igtl_frac_to_nanosec(fraction);
        link.wrenches.push_back({double(NowNs(CLOCK_MONOTONIC) - link.start_ns) * 1e-9,
                                 name == "tubeplan_force", sensor->GetValue(0), sensor->GetValue(1),
                                 sensor->GetValue(2),
                                 seconds != 0 ? double(arrived_ns - echoed_ns) * 1e-3 : -1.0});
      }
    } else {
      ++link.other;
    }
    used += IGTL_HEADER_SIZE + std::size_t(raw.body_size);
  }
  in.erase(in.begin(), in.begin() + std::ptrdiff_t(used));
}

// Streams the poses on absolute deadlines and takes the wrenches between them, until the client
// closes, a fault option or a signal ends it, or the link fails; returns what ended it.
std::string Stream(const Options& o, const tubeplan::trajectories::Trajectory& trajectory,
                   Link& link) {
  const auto period_ns = std::int64_t(std::llround(1e9 / o.rate_hz));
  link.start_ns = NowNs(CLOCK_MONOTONIC);
  link.start_realtime_ns = NowNs(CLOCK_REALTIME);
  std::int64_t next_ns = link.start_ns;
  std::size_t cursor = 0;
  const double t0 = trajectory.samples.front().t_s;
  for (;;) {
    if (g_signal.load() != 0) return "a signal";
    const std::int64_t now_ns = NowNs(CLOCK_MONOTONIC);
    const double elapsed_s = double(now_ns - link.start_ns) * 1e-9;
    if (o.close_after_s > 0.0 && elapsed_s >= o.close_after_s) return "--close-after";
    if (elapsed_s >= o.max_time_s) return "--max-time";
    if (now_ns >= next_ns) {
      const bool streaming = !(o.stop_after_s > 0.0 && elapsed_s >= o.stop_after_s);
      if (streaming) {
        std::string failed;
        if (!SendPose(o, trajectory, t0, cursor, link, failed)) return failed;
      }
      next_ns += period_ns;
      // Absolute deadlines; after a stall of more than 100 ms start afresh instead of bursting.
      if (now_ns - next_ns > 100'000'000) next_ns = now_ns + period_ns;
    }
    // Wait for a wrench until the next deadline.
    pollfd p{link.fd, POLLIN, 0};
    const std::int64_t wait_ns = std::max<std::int64_t>(0, next_ns - NowNs(CLOCK_MONOTONIC));
    timespec timeout{time_t(wait_ns / 1'000'000'000), long(wait_ns % 1'000'000'000)};
    if (ppoll(&p, 1, &timeout, nullptr) <= 0) continue;
    unsigned char chunk[4096];
    const ssize_t got = recv(link.fd, chunk, sizeof chunk, 0);
    if (got == 0) return "the client closed the connection";
    if (got < 0) {
      if (errno == EINTR || errno == EAGAIN) continue;
      return std::string("receiving: ") + std::strerror(errno);
    }
    const std::int64_t arrived_ns = NowNs(CLOCK_REALTIME);
    link.in.insert(link.in.end(), chunk, chunk + got);
    TakeMessages(link, arrived_ns);
  }
}

// --wrenches: every wrench received, one CSV row each.
void WriteWrenches(const std::string& path, const std::vector<Wrench>& wrenches) {
  std::ofstream out(path);
  out << "t_s,kind,x,y,z,round_trip_us\n";
  char row[256];
  for (const Wrench& w : wrenches) {
    std::snprintf(row, sizeof row, "%.6f,%s,%.17g,%.17g,%.17g,%.1f\n", w.t_s,
                  w.force ? "force" : "torque", w.x, w.y, w.z, w.round_trip_us);
    out << row;
  }
  if (!out) std::cerr << "igtl-bridge: error: cannot write " << path << "\n";
}

// The summary line: poses and faults, wrenches, the largest and last force, round trips.
void PrintSummary(const std::string& ended, const Link& link) {
  std::vector<double> round_trips;
  double max_force_N = 0.0;
  const Wrench* last_force = nullptr;
  long forces = 0;
  for (const Wrench& w : link.wrenches) {
    if (!w.force) continue;
    ++forces;
    last_force = &w;
    max_force_N = std::max(max_force_N, std::sqrt(w.x * w.x + w.y * w.y + w.z * w.z));
    if (w.round_trip_us >= 0.0) round_trips.push_back(w.round_trip_us);
  }
  std::printf(
      "igtl-bridge: ended (%s): sent %ld poses, dropped %ld, delayed %ld in %ld pauses; received "
      "%ld wrenches (%ld bad, %ld other messages); max |force| %.3f N, last force (%g, %g, %g) N; "
      "round trip pose to wrench: median %.0f us, p99 %.0f us, max %.0f us\n",
      ended.c_str(), link.poses, link.dropped, link.delayed, link.pauses, forces, link.bad_crc,
      link.other, max_force_N, last_force ? last_force->x : 0.0, last_force ? last_force->y : 0.0,
      last_force ? last_force->z : 0.0, Percentile(round_trips, 0.5), Percentile(round_trips, 0.99),
      Percentile(round_trips, 1.0));
}

int Run(const Options& o) {
  const tubeplan::io::TrajectoryLoadResult loaded = tubeplan::io::LoadTrajectoryFile(o.trajectory);
  std::cerr << loaded.diagnostics.FormatAll();
  if (!loaded.trajectory) return 2;
  const int listener = Listen(o);
  if (listener < 0) return 2;
  Link link;
  link.fd = AcceptOne(o, listener);
  if (link.fd < 0) return 1;
  link.transform->SetDeviceName("igtl-bridge");
  const std::string ended = Stream(o, *loaded.trajectory, link);
  close(link.fd);
  if (!o.wrenches.empty()) WriteWrenches(o.wrenches, link.wrenches);
  PrintSummary(ended, link);
  return link.bad_crc == 0 ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  CLI::App app(
      "An emulated OpenIGTLink haptic bridge: streams a trajectory's poses as TRANSFORM "
      "messages to one client and records the wrenches it sends back (docs/live.md).",
      "igtl-bridge");
  app.add_option("trajectory", o.trajectory, "trajectory CSV (the repository's format)")
      ->required()
      ->check(CLI::ExistingFile);
  app.add_option("--port", o.port, "TCP port; 0: any free one (printed on the first line)")
      ->capture_default_str()
      ->check(CLI::Range(0, 65535));
  app.add_option("--bind", o.bind, "IPv4 address to listen on")->capture_default_str();
  app.add_option("--rate", o.rate_hz, "poses per second")
      ->capture_default_str()
      ->check(CLI::Range(1.0, 10000.0));
  app.add_option("--stop-after", o.stop_after_s,
                 "stop sending poses after S seconds, the connection kept (stale data)")
      ->check(CLI::Range(0.0, 86400.0));
  app.add_option("--close-after", o.close_after_s, "close the connection after S seconds")
      ->check(CLI::Range(0.0, 86400.0));
  app.add_option("--drop", o.drop_probability,
                 "drop each pose with probability P (reproducible with --seed)")
      ->check(CLI::Range(0.0, 1.0));
  app.add_option("--seed", o.seed, "seed of the drops: the same seed drops the same poses")
      ->capture_default_str();
  app.add_option("--delay-ms", o.delay_ms,
                 "pause D ms after every --delay-every poses, then send the held poses at once")
      ->check(CLI::Range(0.0, 86'400'000.0));
  app.add_option("--delay-every", o.delay_every, "poses between the starts of two pauses")
      ->capture_default_str()
      ->check(CLI::Range(1L, 1L << 40));
  app.add_option("--accept-timeout", o.accept_timeout_s, "give up when no client comes in S s")
      ->capture_default_str()
      ->check(CLI::Range(0.001, 86400.0));
  app.add_option("--max-time", o.max_time_s, "end the session after S seconds in any case")
      ->capture_default_str()
      ->check(CLI::Range(0.001, 86400.0));
  app.add_option("--wrenches", o.wrenches, "write the wrenches received to FILE (CSV)");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : 2;
  }
  // A pause holds whole poses and ends before the next one begins.
  const long hold_count = std::lround(o.delay_ms * 1e-3 * o.rate_hz);
  if (o.delay_ms > 0.0 && (hold_count < 1 || hold_count >= o.delay_every)) {
    std::cerr << "igtl-bridge: error: --delay-ms " << o.delay_ms << " holds " << hold_count
              << " poses at " << o.rate_hz << " poses/s; it must hold at least one and fewer than "
              << "--delay-every (" << o.delay_every << ")\n";
    return 2;
  }
  struct sigaction action {};
  action.sa_handler = OnSignal;
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
  signal(SIGPIPE, SIG_IGN);
  return Run(o);
}

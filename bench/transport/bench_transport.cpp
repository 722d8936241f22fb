// bench-transport: the cluster's transport on loopback.
// - PubSub/<size>/<ipc|tcp>: one message published and received by one subscriber (same thread), i.e.
//   the one-way latency of a message through ZeroMQ and protobuf framing, per size;
// - Throughput8: sim.world-sized messages (a real WorldState of the 43-DoF mannequin) to 8 subscribers,
//   each in its own thread: messages/s delivered to every subscriber;
// - MocapToWorld: a live sim service in-process (1 ms step, sim.world published at the first step after
//   each new mocap frame), 10 000 MocapFrames at 1 kHz: latency from a frame's publication to the
//   reception of the first WorldState computed from it (p50, p99, max, in µs);
// - VethThroughput8/curve:0|1/io_threads:1|2 and VethLatency8/curve:0|1/io_threads:1|2: sim.world over tcp
//   across a veth pair, the publisher in one network namespace and 8 subscribers in another (made by the
//   benchmark with `ip`, deleted after; needs root: skipped with the reason otherwise), plaintext and CURVE,
//   the publisher's context with 1 or 2 ZeroMQ I/O threads (a service's --io-threads): messages/s delivered
//   to every subscriber and the CPU time of the publisher's ZeroMQ threads per message (in all and in the
//   busiest one), and the one-way latency (p50, p99, max) of real WorldStates published at 1 kHz, from the
//   publisher's send time to each subscriber's reception (one clock: same host);
// - VethThroughputSize8/curve:0|1/bytes:64|1024|16384: the throughput case with payloads of those sizes.
#include <benchmark/benchmark.h>
#include <fcntl.h>
#include <sched.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <functional>
#include <optional>
#include <sstream>
#include <thread>

#include "bench_main.hpp"
#include "mannequin/math/so3.hpp"
#include "mannequin/simservice/messages.hpp"
#include "mannequin/simservice/sim_service.hpp"
#include "mannequin/transport/clock.hpp"
#include "mannequin/transport/convert.hpp"
#include "mannequin/transport/publisher.hpp"
#include "mannequin/transport/security.hpp"
#include "mannequin/transport/subscriber.hpp"

using namespace mannequin;
namespace topics = transport::topics;

namespace {
constexpr const char* kSimConfig = "configs/sim/sim_demo.yaml";

// the demo's sim config with its mannequin and controller files found from any working directory
simservice::SimServiceConfig simDemoConfig() {
  simservice::SimServiceConfig cfg = simservice::loadSimConfig(mannequin::bench::dataFile(kSimConfig));
  for (auto& m : cfg.mannequins) {
    m.config = mannequin::bench::dataFile(m.config);
    if (!m.controller.empty()) m.controller = mannequin::bench::dataFile(m.controller);
  }
  return cfg;
}

// the ipc sockets' directory, made on first use and removed when the executable exits
struct IpcDir {
  std::string path;
  ~IpcDir() {
    std::error_code ec;  // a destructor does not throw: what cannot be removed stays
    std::filesystem::remove_all(path, ec);
  }
};

std::string ipcDir() {
  static const IpcDir dir{[] {
    auto p = std::filesystem::temp_directory_path() / ("bench-transport-" + std::to_string(getpid()));
    std::filesystem::create_directories(p);
    return p.string();
  }()};
  return dir.path;
}

/// The count of the subscriber that has received the fewest messages.
std::uint64_t fewestReceived(const std::vector<std::atomic<std::uint64_t>>& counts) {
  std::uint64_t m = ~0ull;
  for (const auto& c : counts) m = std::min<std::uint64_t>(m, c.load());
  return m;
}

void waitSubscribed(transport::Publisher& pub, std::uint64_t n) {
  while (pub.subscriptions() < n) {
    pub.poll();
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
}

void PubSub(benchmark::State& state) {
  const std::size_t size = static_cast<std::size_t>(state.range(0));
  const bool tcp = state.range(1) == 1;
  zmq::context_t ctx;
  transport::Publisher pub(ctx, {"bench", {tcp ? "tcp://127.0.0.1:0" : "ipc://" + ipcDir() + "/pubsub"}});
  transport::Subscriber sub(ctx, {"bench", {pub.boundEndpoints()[0]}});
  int got = 0;
  sub.subscribeRaw("bench", [&](std::string_view, std::string_view, const transport::Received&) { ++got; });
  waitSubscribed(pub, 1);
  const std::string payload(size, 'x');
  for (auto _ : state) {
    const int before = got;
    pub.publishRaw("bench.payload", payload);
    while (got == before) sub.poll(std::chrono::microseconds(0));
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * size));
  state.SetLabel(tcp ? "tcp loopback" : "ipc");
}
BENCHMARK(PubSub)->ArgsProduct({{64, 2048, 16384}, {0, 1}})->UseRealTime()->Unit(benchmark::kMicrosecond);

// a WorldState exactly as the sim publishes it (the demo's 43-DoF mannequin, 6 control frames)
std::string worldPayload() {
  const simservice::SimServiceConfig cfg = simDemoConfig();
  sim::World world(simservice::buildMannequins(cfg), cfg.world);
  world.step();
  v1::WorldState w;
  simservice::toWorldState(world, nullptr, false, false, w);
  return w.SerializeAsString();
}

void Throughput8(benchmark::State& state) {
  constexpr int kSubs = 8;
  zmq::context_t ctx(2);
  transport::PublisherOptions po{"sim", {"ipc://" + ipcDir() + "/throughput"}};
  po.send_hwm = 100000;
  transport::Publisher pub(ctx, po);
  std::atomic<bool> done{false};
  std::vector<std::atomic<std::uint64_t>> counts(kSubs);
  std::vector<std::thread> threads;
  for (int i = 0; i < kSubs; ++i)
    threads.emplace_back([&, i] {
      transport::SubscriberOptions so{"sub" + std::to_string(i), {po.endpoints[0]}};
      so.receive_hwm = 100000;
      transport::Subscriber sub(ctx, so);
      sub.subscribeRaw("sim.world", [&](std::string_view, std::string_view, const transport::Received&) { ++counts[i]; });
      while (!done.load()) sub.poll(std::chrono::milliseconds(1));
    });
  waitSubscribed(pub, kSubs);
  const std::string payload = worldPayload();
  std::uint64_t sent = 0;
  const std::int64_t t0 = transport::steadyNs();
  for (auto _ : state) {
    pub.publishRaw("sim.world", payload);
    ++sent;
  }
  // wait until every subscriber has everything (or 10 s)
  const auto minCount = [&] { return fewestReceived(counts); };
  while (minCount() < sent && (transport::steadyNs() - t0) < 10'000'000'000LL) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  const double seconds = (transport::steadyNs() - t0) * 1e-9;
  done = true;
  for (auto& t : threads) t.join();
  state.counters["msg_per_s_per_subscriber"] = static_cast<double>(minCount()) / seconds;
  state.counters["delivered_fraction"] = static_cast<double>(minCount()) / static_cast<double>(sent);
  state.counters["payload_bytes"] = static_cast<double>(payload.size());
}
BENCHMARK(Throughput8)->Iterations(50000)->UseRealTime()->Unit(benchmark::kMicrosecond);

void MocapToWorld(benchmark::State& state) {
  const int frames = static_cast<int>(state.range(0));
  for (auto _ : state) {
    zmq::context_t ctx;
    const std::string dir = ipcDir();
    transport::Publisher mocap(ctx, {"mocap", {"ipc://" + dir + "/m2w-mocap"}});
    simservice::SimServiceConfig cfg = simDemoConfig();
    cfg.mode = simservice::Mode::kLive;
    cfg.publish = {"ipc://" + dir + "/m2w-sim"};
    cfg.connect = {"ipc://" + dir + "/m2w-mocap"};
    cfg.collision.mode = simservice::CollisionMode::kNone;
    cfg.publish_on_mocap = true;
    cfg.world.interpolation_delay = 0.0;
    simservice::SimService sim(cfg, ctx);
    std::atomic<bool> stop{false};
    std::thread runner([&] { sim.run(stop); });
    transport::SubscriberOptions so{"bench", {"ipc://" + dir + "/m2w-sim"}};
    transport::Subscriber out(ctx, so);
    std::vector<std::int64_t> sent(frames + 1, 0);
    std::vector<double> latency_us;
    latency_us.reserve(frames);
    std::uint64_t last_seq = 0;
    out.subscribe(topics::kSimWorld, std::function<void(const v1::WorldState&, const transport::Received&)>(
                                         [&](const v1::WorldState& w, const transport::Received& r) {
                                           const std::uint64_t seq = w.mocap().sequence();
                                           if (seq <= last_seq || seq >= sent.size()) return;  // not the first state of this frame
                                           last_seq = seq;
                                           latency_us.push_back(static_cast<double>(r.receive_time_ns - w.mocap().send_time_ns()) * 1e-3);
                                         }));
    waitSubscribed(mocap, 2);
    bool connected = false;
    out.subscribe(topics::kHeartbeat, std::function<void(const v1::Heartbeat&)>([&](const v1::Heartbeat&) { connected = true; }));
    while (!connected) out.poll(std::chrono::milliseconds(5));
    v1::MocapFrame f;
    const char* names[] = {"pelvis", "head", "hand_l", "hand_r", "foot_l", "foot_r"};
    const math::Vector3 at[] = {{0, 0, 0.95}, {0, 0, 1.65}, {0.1, 0.3, 0.9}, {0.1, -0.3, 0.9}, {0, 0.1, 0.08}, {0, -0.1, 0.08}};
    const std::int64_t start = transport::steadyNs();
    for (int k = 0; k < frames; ++k) {
      // 1 kHz: wait for the slot while reading the sim's output
      const std::int64_t due = start + static_cast<std::int64_t>(k) * 1'000'000;
      while (transport::steadyNs() < due) out.poll(std::chrono::microseconds(std::max<std::int64_t>(0, (due - transport::steadyNs()) / 1000)));
      f.Clear();
      f.mutable_header()->set_stamp_ns(static_cast<std::int64_t>(k) * 1'000'000);
      f.set_frame_number(k);
      for (int b = 0; b < 6; ++b) {
        auto* rb = f.add_bodies();
        rb->set_name(names[b]);
        rb->set_tracked(true);
        rb->set_quality(1);
        math::SE3 H;
        H.p = at[b] + math::Vector3(0.05 * std::sin(k * 0.01), 0, 0);
        transport::toMsg(H, *rb->mutable_pose());
      }
      mocap.publish(topics::kMocapFrame, f);
      sent[f.header().sequence()] = f.header().send_time_ns();
    }
    const std::int64_t tail = transport::steadyNs();
    while (transport::steadyNs() - tail < 200'000'000) out.poll(std::chrono::milliseconds(5));
    stop = true;
    runner.join();
    std::sort(latency_us.begin(), latency_us.end());
    auto pct = [&](double p) { return latency_us.empty() ? -1.0 : latency_us[static_cast<std::size_t>(p * (latency_us.size() - 1))]; };
    state.counters["frames"] = frames;
    state.counters["measured"] = static_cast<double>(latency_us.size());
    state.counters["p50_us"] = pct(0.5);
    state.counters["p99_us"] = pct(0.99);
    state.counters["max_us"] = latency_us.empty() ? -1.0 : latency_us.back();
    state.counters["sim_overruns"] = static_cast<double>(sim.stats().overruns);
  }
}
BENCHMARK(MocapToWorld)->Arg(10000)->Iterations(1)->UseRealTime()->Unit(benchmark::kMillisecond);

// ---- tcp over a veth pair between two network namespaces ----

/// Two network namespaces joined by a veth pair (10.231.0.1/24 in `a`, 10.231.0.2/24 in `b`), made with
/// `ip` for one benchmark and deleted by the destructor. error() says why not when it could not be made.
class VethPair {
 public:
  VethPair() : a_("mqbench" + std::to_string(getpid()) + "a"), b_("mqbench" + std::to_string(getpid()) + "b") {
    if (::geteuid() != 0) {
      error_ = "needs root (CAP_SYS_ADMIN, CAP_NET_ADMIN) to make network namespaces and a veth pair";
      return;
    }
    for (const char* p : {"/usr/sbin/ip", "/sbin/ip", "/usr/bin/ip", "/bin/ip"})
      if (::access(p, X_OK) == 0) ip_ = p;
    if (ip_.empty()) {
      error_ = "no 'ip' tool (iproute2)";
      return;
    }
    const std::vector<std::vector<std::string>> steps = {
        {"netns", "add", a_},
        {"netns", "add", b_},
        {"link", "add", "veth0", "netns", a_, "type", "veth", "peer", "name", "veth0", "netns", b_},
        {"-n", a_, "addr", "add", std::string(kAddressA) + "/24", "dev", "veth0"},
        {"-n", b_, "addr", "add", std::string(kAddressB) + "/24", "dev", "veth0"},
        {"-n", a_, "link", "set", "lo", "up"},
        {"-n", b_, "link", "set", "lo", "up"},
        {"-n", a_, "link", "set", "veth0", "up"},
        {"-n", b_, "link", "set", "veth0", "up"},
    };
    for (const auto& args : steps) {
      if (args[0] == "netns" && args[1] == "add") created_.push_back(args[2]);
      if (!run(args)) {
        std::string cmd = "ip";
        for (const auto& x : args) cmd += " " + x;
        error_ = cmd + " failed (no privilege for network namespaces here?)";
        return;
      }
    }
  }
  ~VethPair() {
    for (const std::string& ns : created_) run({"netns", "del", ns});
  }
  VethPair(const VethPair&) = delete;
  VethPair& operator=(const VethPair&) = delete;
  const std::string& error() const { return error_; }
  const std::string& a() const { return a_; }
  const std::string& b() const { return b_; }
  static constexpr const char* kAddressA = "10.231.0.1";
  static constexpr const char* kAddressB = "10.231.0.2";

 private:
  bool run(const std::vector<std::string>& args) const {
    std::vector<char*> argv{const_cast<char*>(ip_.c_str())};
    for (const std::string& x : args) argv.push_back(const_cast<char*>(x.c_str()));
    argv.push_back(nullptr);
    const pid_t pid = ::fork();
    if (pid == 0) {
      const int null = ::open("/dev/null", O_WRONLY);
      if (null >= 0) {
        ::dup2(null, STDOUT_FILENO);
        ::dup2(null, STDERR_FILENO);
      }
      ::execv(argv[0], argv.data());
      ::_exit(127);
    }
    if (pid <= 0) return false;
    int status = 0;
    if (::waitpid(pid, &status, 0) != pid) return false;
    return WIFEXITED(status) && WEXITSTATUS(status) == 0;
  }
  std::string a_, b_, ip_, error_;
  std::vector<std::string> created_;
};

/// The calling thread in network namespace `ns` (ip netns's /run/netns/NS) until destruction; sockets
/// and the ZeroMQ I/O threads a context starts from this thread belong to that namespace.
class InNetns {
 public:
  explicit InNetns(const std::string& ns)
      : self_(::open("/proc/thread-self/ns/net", O_RDONLY | O_CLOEXEC)), target_(::open(("/run/netns/" + ns).c_str(), O_RDONLY | O_CLOEXEC)) {
    if (self_ < 0 || target_ < 0 || ::setns(target_, CLONE_NEWNET) != 0)
      throw std::runtime_error("cannot enter network namespace " + ns + ": " + std::strerror(errno));
  }
  ~InNetns() {
    if (self_ >= 0 && ::setns(self_, CLONE_NEWNET) != 0) std::fprintf(stderr, "bench-transport: cannot leave a network namespace\n");
    if (self_ >= 0) ::close(self_);
    if (target_ >= 0) ::close(target_);
  }
  InNetns(const InNetns&) = delete;
  InNetns& operator=(const InNetns&) = delete;

 private:
  int self_, target_;
};

/// The CURVE keys of one publisher and its subscribers (plaintext: none).
struct VethKeys {
  std::optional<transport::CurveServerOptions> server;
  std::optional<transport::CurveClientOptions> client;
  explicit VethKeys(bool curve) {
    if (!curve) return;
    const transport::CurveKeyPair s = transport::generateCurveKeyPair(), c = transport::generateCurveKeyPair();
    server = transport::CurveServerOptions{s.secret_key, {c.public_key}};
    transport::CurveClientOptions o;
    o.public_key = c.public_key;
    o.secret_key = c.secret_key;
    o.server_public_key = s.public_key;
    client = o;
  }
};

/// 8 subscribers to sim.world in namespace `ns`, each in its own thread with its own context (its I/O
/// thread in that namespace too); `on` is called in the subscriber's thread.
class VethSubscribers {
 public:
  static constexpr int kCount = 8;
  using Handler = std::function<void(int, std::string_view, const transport::Received&)>;
  VethSubscribers(const std::string& ns, const std::string& endpoint, const std::optional<transport::CurveClientOptions>& curve, Handler on) {
    for (int i = 0; i < kCount; ++i)
      threads_.emplace_back([this, i, ns, endpoint, curve, on] {
        try {
          InNetns in(ns);
          zmq::context_t ctx(1);
          transport::SubscriberOptions so{"sub" + std::to_string(i), {endpoint}, 100000, 10000, curve};
          transport::Subscriber sub(ctx, so);
          sub.subscribeRaw("sim.world", [&](std::string_view, std::string_view payload, const transport::Received& r) { on(i, payload, r); });
          while (!done_.load()) sub.poll(std::chrono::milliseconds(1));
        } catch (const std::exception& e) {
          std::fprintf(stderr, "bench-transport: subscriber %d: %s\n", i, e.what());
        }
      });
  }
  ~VethSubscribers() {
    done_ = true;
    for (auto& t : threads_) t.join();
  }
  VethSubscribers(const VethSubscribers&) = delete;
  VethSubscribers& operator=(const VethSubscribers&) = delete;

 private:
  std::atomic<bool> done_{false};
  std::vector<std::thread> threads_;
};

/// The ids of this process's threads (/proc/self/task).
std::vector<int> threadIds() {
  std::vector<int> ids;
  for (const auto& e : std::filesystem::directory_iterator("/proc/self/task")) ids.push_back(std::stoi(e.path().filename().string()));
  std::sort(ids.begin(), ids.end());
  return ids;
}

/// CPU time (user + system, s) of the given threads of this process (/proc/self/task/TID/stat).
double threadsCpuSeconds(const std::vector<int>& tids) {
  double s = 0;
  for (const int tid : tids) {
    std::ifstream in("/proc/self/task/" + std::to_string(tid) + "/stat");
    std::string line;
    std::getline(in, line);
    const auto close = line.rfind(')');
    if (close == std::string::npos) continue;
    std::istringstream rest(line.substr(close + 2));
    std::string field;
    unsigned long long utime = 0, stime = 0;
    for (int k = 3; k <= 15 && rest >> field; ++k) {  // fields 14, 15: utime, stime (clock ticks)
      if (k == 14) utime = std::stoull(field);
      if (k == 15) stime = std::stoull(field);
    }
    s += static_cast<double>(utime + stime) / static_cast<double>(::sysconf(_SC_CLK_TCK));
  }
  return s;
}

/// `payload` as fast as the publisher queues it (one message per iteration) to 8 subscribers across a veth pair.
void vethThroughput(benchmark::State& state, bool curve, int io_threads, const std::string& payload) {
  VethPair veth;
  if (!veth.error().empty()) {
    state.SkipWithError(("skipped: " + veth.error()).c_str());
    for (auto _ : state) {
    }
    return;
  }
  const VethKeys keys(curve);
  std::vector<std::atomic<std::uint64_t>> counts(VethSubscribers::kCount);
  const std::string endpoint = "tcp://" + std::string(VethPair::kAddressA) + ":5700";
  InNetns in(veth.a());  // the publisher (this thread, its context's I/O thread) in namespace a
  {
    zmq::context_t ctx(io_threads);
    const std::vector<int> before = threadIds();
    transport::PublisherOptions po{"sim", {endpoint}};
    po.send_hwm = 100000;
    po.curve = keys.server;
    transport::Publisher pub(ctx, po);
    // the publisher's context's threads (its I/O threads, the reaper, the ZAP handler with CURVE): started
    // by its first socket, before any subscriber's
    std::vector<int> pub_threads;
    std::ranges::set_difference(threadIds(), before, std::back_inserter(pub_threads));
    VethSubscribers subs(veth.b(), endpoint, keys.client,
                         [&](int i, std::string_view, const transport::Received&) { ++counts[static_cast<std::size_t>(i)]; });
    waitSubscribed(pub, VethSubscribers::kCount);
    std::uint64_t sent = 0;
    std::vector<double> cpu0;
    for (const int tid : pub_threads) cpu0.push_back(threadsCpuSeconds({tid}));
    const std::int64_t t0 = transport::steadyNs();
    for (auto _ : state) {
      pub.publishRaw("sim.world", payload);
      ++sent;
    }
    const auto minCount = [&] { return fewestReceived(counts); };
    while (minCount() < sent && (transport::steadyNs() - t0) < 20'000'000'000LL) {
      pub.poll();
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    const double seconds = static_cast<double>(transport::steadyNs() - t0) * 1e-9;
    // what the sim's host pays: CPU of the publisher's ZeroMQ threads per message (all 8 copies), in all
    // and in the busiest one (with free cores, the publisher cannot go faster than that thread)
    double total = 0, busiest = 0;
    for (std::size_t k = 0; k < pub_threads.size(); ++k) {
      const double used = threadsCpuSeconds({pub_threads[k]}) - cpu0[k];
      total += used;
      busiest = std::max(busiest, used);
    }
    state.counters["pub_io_cpu_us_per_msg"] = total * 1e6 / static_cast<double>(sent);
    state.counters["pub_busiest_thread_cpu_us_per_msg"] = busiest * 1e6 / static_cast<double>(sent);
    state.counters["msg_per_s_per_subscriber"] = static_cast<double>(minCount()) / seconds;
    state.counters["delivered_fraction"] = static_cast<double>(minCount()) / static_cast<double>(sent);
    state.counters["payload_bytes"] = static_cast<double>(payload.size());
  }
  state.SetLabel(std::string(curve ? "veth tcp, CURVE" : "veth tcp, plaintext") + ", publisher io_threads " + std::to_string(io_threads));
}

void VethThroughput8(benchmark::State& state) {
  vethThroughput(state, state.range(0) == 1, static_cast<int>(state.range(1)), worldPayload());
}
/// The same with a payload of `bytes` (not a WorldState: the subscribers do not parse it), 1 I/O thread.
void VethThroughputSize8(benchmark::State& state) {
  vethThroughput(state, state.range(0) == 1, 1, std::string(static_cast<std::size_t>(state.range(1)), 'x'));
}
BENCHMARK(VethThroughputSize8)->ArgNames({"curve", "bytes"})->ArgsProduct({{0, 1}, {64, 1024, 16384}})->Iterations(20000)->UseRealTime()->Unit(benchmark::kMicrosecond);
BENCHMARK(VethThroughput8)->ArgNames({"curve", "io_threads"})->ArgsProduct({{0, 1}, {1, 2}})->Iterations(20000)->UseRealTime()->Unit(benchmark::kMicrosecond);

void VethLatency8(benchmark::State& state) {
  const bool curve = state.range(0) == 1;
  const int io_threads = static_cast<int>(state.range(1));
  const int messages = 2000;  // at 1 kHz
  VethPair veth;
  if (!veth.error().empty()) {
    state.SkipWithError(("skipped: " + veth.error()).c_str());
    for (auto _ : state) {
    }
    return;
  }
  const VethKeys keys(curve);
  const std::string endpoint = "tcp://" + std::string(VethPair::kAddressA) + ":5701";
  InNetns in(veth.a());
  for (auto _ : state) {
    std::vector<std::vector<double>> latency_us(VethSubscribers::kCount);
    for (auto& l : latency_us) l.reserve(messages);
    zmq::context_t ctx(io_threads);
    transport::PublisherOptions po{"sim", {endpoint}};
    po.curve = keys.server;
    transport::Publisher pub(ctx, po);
    {
      VethSubscribers subs(veth.b(), endpoint, keys.client, [&](int i, std::string_view payload, const transport::Received& r) {
        v1::WorldState w;  // parsed as a render node would
        if (w.ParseFromArray(payload.data(), static_cast<int>(payload.size())) && w.header().send_time_ns() > 0)
          latency_us[static_cast<std::size_t>(i)].push_back(static_cast<double>(r.receive_time_ns - w.header().send_time_ns()) * 1e-3);
      });
      waitSubscribed(pub, VethSubscribers::kCount);
      const simservice::SimServiceConfig cfg = simDemoConfig();
      sim::World world(simservice::buildMannequins(cfg), cfg.world);
      world.step();
      v1::WorldState w;
      simservice::toWorldState(world, nullptr, false, false, w);
      const std::int64_t start = transport::steadyNs();
      for (int k = 0; k < messages; ++k) {
        const std::int64_t due = start + static_cast<std::int64_t>(k) * 1'000'000;
        while (transport::steadyNs() < due) std::this_thread::sleep_for(std::chrono::microseconds(50));
        w.set_step(static_cast<std::uint64_t>(k));
        pub.publish(topics::kSimWorld, w);
      }
      const std::int64_t tail = transport::steadyNs();
      while (transport::steadyNs() - tail < 300'000'000) {
        pub.poll();
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
      }
    }
    std::vector<double> all;
    for (const auto& l : latency_us) all.insert(all.end(), l.begin(), l.end());
    std::sort(all.begin(), all.end());
    auto pct = [&](double p) { return all.empty() ? -1.0 : all[static_cast<std::size_t>(p * static_cast<double>(all.size() - 1))]; };
    state.counters["received_fraction"] = static_cast<double>(all.size()) / (static_cast<double>(messages) * VethSubscribers::kCount);
    state.counters["p50_us"] = pct(0.5);
    state.counters["p99_us"] = pct(0.99);
    state.counters["max_us"] = all.empty() ? -1.0 : all.back();
  }
  state.SetLabel(std::string(curve ? "veth tcp, CURVE, 1 kHz" : "veth tcp, plaintext, 1 kHz") + ", publisher io_threads " + std::to_string(io_threads));
}
BENCHMARK(VethLatency8)->ArgNames({"curve", "io_threads"})->ArgsProduct({{0, 1}, {1, 2}})->Iterations(1)->UseRealTime()->Unit(benchmark::kMillisecond);

}  // namespace

MANNEQUIN_BENCHMARK_MAIN("bench-transport", kSimConfig)

// dds_bench: map blocks from a MapPublisher to a reader in another process over loopback.
// Prints blocks/s and MB/s at two block sizes, publish-to-receive latency p50/p99 at 10 Hz map
// updates, and ddsperf's rate for the same payload sizes in the same run.
//   dds_bench [seconds [repetitions]]   (default 3 s a throughput run, median of 3)
//   dds_bench --throughput CELLS SECONDS [RATE [listener|waitset]]  (one run of ours only, for
//   profiling; RATE blocks/s paces the writer, 0 (default): as fast as it goes; the reader's
//   MapClient takes by poll() from a waitset thread unless `listener`: take_on_receive)
// The reader is this binary again (`dds_bench --reader ... listener|waitset`). CYCLONEDDS_URI
// defaults to the loopback XML of the source tree, so nothing leaves 127.0.0.1.
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <iostream>
#include <random>
#include <span>
#include <sstream>
#include <string>
#include <thread>
#include <unordered_map>
#include <vector>

#include "child_pipe.hpp"
#include "semap/dds_idl/block_cdr.hpp"
#include "semap/dds_idl/block_codec.hpp"
#include "semap/dds_idl/converters.hpp"
#include "semap/dds_idl/map_client.hpp"
#include "semap/dds_idl/map_publisher.hpp"
#include "semap/dds_idl/reader.hpp"
#include "semap/dds_idl/topic_names.hpp"

namespace sd = semap::dds_idl;
using semap::common::Stamp;
using Clock = std::chrono::steady_clock;
using semap::bench::Pipe;

namespace {

constexpr std::uint16_t kClasses = 8;

// Serialized size of a block without evidence (XCDR1): header, key, shape, four sequences.
std::size_t block_bytes(std::uint16_t cells) {
  const std::size_t n = static_cast<std::size_t>(cells) * cells * cells;
  std::size_t s = 8 + 4 + 4;            // stamp, frame_id "map"
  s += 12 + 4 + 2 + 2 + 4;              // key, resolution, shape, version
  s += 4 + n;                           // state
  s = (s + 3) / 4 * 4 + 4 + 2 * n;      // argmax_class (aligned length)
  s = (s + 3) / 4 * 4 + 4 + 4 * n + 4;  // variance, empty evidence
  return s;
}

// CPU seconds used so far by this process, all threads (DDS's own threads included).
double cpu_seconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  const auto secs = [](const timeval& t) {
    return static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_usec);
  };
  return secs(u.ru_utime) + secs(u.ru_stime);
}

// CPU seconds used so far by the calling thread.
double thread_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

// ---- reader side (child process) ----

// Throughput: MapClient itself takes the blocks, on its poll() thread ("waitset": woken by the
// reader's waitset) or on Cyclone's receive thread ("listener": take_on_receive, ddsperf's
// default subscriber mode). This thread only watches the counters: time from the first block
// seen to the last, at 2 ms granularity (under 0.1 % of a 3 s run).
int run_client_reader(int domain, const std::string& ns, const std::string& mode) {
  sd::Participant p(domain);
  sd::MapClientConfig cfg;
  cfg.ns = ns;
  cfg.take_on_receive = mode == "listener";
  sd::MapClient client(p, cfg);
  while (client.matched_writers() == 0) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  std::cout << "ready" << std::endl;
  const double cpu0 = cpu_seconds();
  const auto start = Clock::now();
  std::uint64_t seen = 0;
  Clock::time_point first = start, last = start;
  for (;;) {
    client.wait_for_blocks(SIZE_MAX, std::chrono::milliseconds(2));
    const sd::MapClientCounters c = client.counters();
    const std::uint64_t n = c.accepted + c.stale + c.rejected_total();
    const auto now = Clock::now();
    if (n != seen) {
      if (seen == 0) first = now;
      last = now;
      seen = n;
    }
    const auto idle = now - (seen == 0 ? start : last);
    if (idle > std::chrono::milliseconds(seen == 0 ? 20000 : 1500)) break;
  }
  // The reader's CPU time includes the final idle wait, which costs next to nothing.
  std::cout << "result " << seen << " " << std::chrono::duration<double>(last - first).count()
            << " " << seen - client.counters().accepted << " " << cpu_seconds() - cpu0 << std::endl;
  return 0;
}

// Latency: every block's stamp against its arrival, taken from a waitset thread; per block the
// work MapClient does (read from the serialised bytes, check, swap into the map entry).
struct LatencySink {
  std::uint64_t n = 0, bad = 0;
  Clock::time_point first, last;
  std::vector<double> latencies_us;
  sd::BlockLimits limits;
  std::unordered_map<semap::common::BlockIndex, sd::BlockSnapshot, semap::common::BlockIndexHash>
      map;
  sd::BlockSnapshot scratch;

  void operator()(std::span<const std::uint8_t> cdr, const dds_sample_info_t&) {
    const Stamp now = Stamp::now();
    Stamp stamp;
    if (sd::read_block_cdr(cdr, scratch, stamp).ok() && sd::check_block(scratch, limits).ok()) {
      std::swap(map[scratch.index], scratch);
    } else {
      ++bad;
    }
    if (n == 0) first = Clock::now();
    last = Clock::now();
    ++n;
    latencies_us.push_back(static_cast<double>(now.ns - stamp.ns) * 1e-3);
  }
};

int run_latency_reader(int domain, const std::string& ns) {
  sd::Participant p(domain);
  sd::Topic<sd::msg::SemanticMapBlock> topic(p, sd::topic_name(ns, sd::SemapTopic::kMapBlocks));
  sd::Reader<sd::msg::SemanticMapBlock> reader(p, topic, sd::topic_qos(sd::SemapTopic::kMapBlocks));
  while (reader.matched() == 0) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  std::cout << "ready" << std::endl;
  const double cpu0 = cpu_seconds();
  LatencySink sink;
  while (reader.wait(std::chrono::milliseconds(sink.n == 0 ? 20000 : 1500))) {
    reader.take_each_cdr(sink);
  }
  const double secs = std::chrono::duration<double>(sink.last - sink.first).count();
  std::cout << "result " << sink.n << " " << secs << " " << sink.bad << " " << cpu_seconds() - cpu0;
  if (!sink.latencies_us.empty()) {
    std::vector<double> l = sink.latencies_us;
    std::sort(l.begin(), l.end());
    const auto pct = [&](double q) {
      return l[std::min(l.size() - 1, static_cast<std::size_t>(q * static_cast<double>(l.size())))];
    };
    std::cout << " " << pct(0.5) << " " << pct(0.99) << " " << l.back();
  }
  std::cout << std::endl;
  return 0;
}

// ---- writer side ----

sd::MapDescription description(std::uint16_t cells) {
  sd::MapDescription d;
  d.resolution = 0.1f;
  d.block_cells = cells;
  d.num_classes = kClasses;
  return d;
}

sd::BlockSnapshot block(semap::common::BlockIndex index, std::uint16_t cells,
                        std::uint32_t version) {
  sd::BlockSnapshot b = sd::BlockSnapshot::empty(index, 0.1f, cells, kClasses, false);
  b.version = version;
  for (std::size_t i = 0; i < b.cell_count(); ++i) {
    b.state[i] = static_cast<semap::common::CellState>(i % 3);
    b.argmax_class[i] = static_cast<std::uint16_t>(i % kClasses);
    b.variance[i] = 0.01f;
  }
  return b;
}

std::string self_path() {
  char buf[4096];
  const ssize_t n = readlink("/proc/self/exe", buf, sizeof buf - 1);
  if (n <= 0) throw std::runtime_error("readlink /proc/self/exe");
  return std::string(buf, static_cast<std::size_t>(n));
}

struct Throughput {
  double blocks_per_s = 0;
  double mb_per_s = 0;
  double written_per_s = 0;
  double writer_cpu_us = 0;  // writer process CPU time per written block
  double reader_cpu_us = 0;  // reader process CPU time per received block
  std::uint64_t written = 0;
  std::uint64_t received = 0;
  std::uint64_t bad = 0;
  std::uint64_t write_timeouts = 0;  // writes that waited max_blocking_time for the reader
  double writer_thread_busy = 0;     // writing thread's CPU time / wall time: < 1 = waiting
  // Context switches of the writing thread: voluntary ones block in dds_write (flow control,
  // locks), involuntary ones are preemption by other processes.
  std::int64_t writer_voluntary_switches = 0;
  std::int64_t writer_involuntary_switches = 0;
};

// One throughput run. rate 0: the writer goes as fast as it can (saturating: with keep-last 1
// the reader takes only the latest version of a block, so versions it was too slow for are
// received by its DDS threads and then replaced unseen). rate > 0: the writer is paced to
// `rate` blocks/s in rounds of 1000, to find the rate the reader takes in full.
Throughput throughput(int domain, std::uint16_t cells, double seconds, double rate = 0.0,
                      const std::string& mode = "waitset") {
  const std::string ns = "bench_tp" + std::to_string(cells);
  Pipe reader(self_path() + " --reader " + std::to_string(domain) + " " + ns + " 0 " + mode);
  sd::Participant p(domain);
  sd::MapPublisherConfig cfg;
  cfg.ns = ns;
  cfg.blocks_hz = 1e6;
  cfg.cloud_hz = 0.0;
  sd::SnapshotStore pub_blocks;
  sd::MapPublisher pub(p, cfg, description(cells), pub_blocks);
  reader.expect("ready");
  while (pub.matched_readers() == 0) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  // 1000 distinct blocks, rewritten in new versions as fast as the writer goes.
  constexpr int kBlocks = 1000;
  std::vector<sd::BlockSnapshot> blocks;
  for (int i = 0; i < kBlocks; ++i)
    blocks.push_back(block({i % 10, i / 10 % 10, i / 100}, cells, 1));
  std::uint64_t written = 0;
  const double cpu0 = cpu_seconds();
  const double thread0 = thread_cpu_seconds();
  rusage switches0{};
  getrusage(RUSAGE_THREAD, &switches0);
  const auto start = Clock::now();
  std::uint32_t version = 1;
  while (Clock::now() - start < std::chrono::duration<double>(seconds)) {
    ++version;
    for (auto& b : blocks) {
      b.version = version;
      pub.changed(pub_blocks.put(b));
    }
    written += pub.publish_changed(Stamp::now());
    if (rate > 0.0) {
      std::this_thread::sleep_until(
          start + std::chrono::duration_cast<Clock::duration>(
                      std::chrono::duration<double>(static_cast<double>(written) / rate)));
    }
  }
  const double wsecs = std::chrono::duration<double>(Clock::now() - start).count();
  const double wcpu = cpu_seconds() - cpu0;
  const double thread_cpu = thread_cpu_seconds() - thread0;
  rusage switches1{};
  getrusage(RUSAGE_THREAD, &switches1);
  std::istringstream r(reader.expect("result").substr(7));
  std::uint64_t n = 0, bad = 0;
  double secs = 0, rcpu = 0;
  r >> n >> secs >> bad >> rcpu;
  Throughput t;
  t.written = written;
  t.received = n;
  t.bad = bad;
  t.blocks_per_s = secs > 0 ? static_cast<double>(n) / secs : 0;
  t.mb_per_s = t.blocks_per_s * static_cast<double>(block_bytes(cells)) / 1e6;
  t.written_per_s = static_cast<double>(written) / wsecs;
  t.write_timeouts = pub.counters().write_timeouts;
  t.writer_thread_busy = thread_cpu / wsecs;
  t.writer_voluntary_switches = switches1.ru_nvcsw - switches0.ru_nvcsw;
  t.writer_involuntary_switches = switches1.ru_nivcsw - switches0.ru_nivcsw;
  t.writer_cpu_us = written > 0 ? 1e6 * wcpu / static_cast<double>(written) : 0;
  t.reader_cpu_us = n > 0 ? 1e6 * rcpu / static_cast<double>(n) : 0;
  return t;
}

// Paced runs at fractions of ddsperf's default rate: the highest whose blocks the reader takes
// in full (at least 99 % of those written) is the figure to set against ddsperf's default,
// whose keep-all writer is held to its reader's pace by flow control, so that every sample it
// sends is taken. The saturating figure instead counts only the versions the reader got to
// before newer ones replaced them. Each step is printed: on a shared machine a stall of the
// reader longer than one round (1000 blocks) loses versions at any rate.
struct Matched {
  double blocks_per_s = 0;
  double reader_cpu_us = 0;
  double writer_cpu_us = 0;
};

Matched matched_rate(int domain, std::uint16_t cells, double seconds, double ddsperf_default,
                     const std::string& mode) {
  Matched best;
  std::printf("  %s, paced writer at %% of ddsperf default: received/s (%% of written)",
              mode.c_str());
  for (double fraction : {0.25, 0.5, 0.75, 0.9, 1.0}) {
    const Throughput t = throughput(domain, cells, seconds, fraction * ddsperf_default, mode);
    const double taken = t.written > 0 ? static_cast<double>(t.received) / t.written : 0.0;
    std::printf(" %.0f%%: %.0f (%.1f%%)", 100.0 * fraction, t.blocks_per_s, 100.0 * taken);
    std::fflush(stdout);
    if (taken >= 0.99 && t.blocks_per_s > best.blocks_per_s) {
      best = {t.blocks_per_s, t.reader_cpu_us, t.writer_cpu_us};
    }
  }
  std::printf("\n");
  return best;
}

struct Latency {
  double p50_us = 0, p99_us = 0, max_us = 0;
  std::uint64_t samples = 0;
};

Latency latency(int domain, std::uint16_t cells, int blocks_per_update, double seconds) {
  const std::string ns = "bench_lat" + std::to_string(blocks_per_update);
  Pipe reader(self_path() + " --reader " + std::to_string(domain) + " " + ns + " 1 waitset");
  sd::Participant p(domain);
  sd::MapPublisherConfig cfg;
  cfg.ns = ns;
  cfg.blocks_hz = 10.0;
  cfg.cloud_hz = 0.0;
  sd::SnapshotStore pub_blocks;
  sd::MapPublisher pub(p, cfg, description(cells), pub_blocks);
  reader.expect("ready");
  while (pub.matched_readers() == 0) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  // Let the reader's side of the match settle too, or the first round arrives as historical
  // (transient-local) data with a stale stamp.
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  const auto start = Clock::now();
  std::uint32_t version = 0;
  while (Clock::now() - start < std::chrono::duration<double>(seconds)) {
    ++version;
    for (int i = 0; i < blocks_per_update; ++i)
      pub.changed(pub_blocks.put(block({i, 0, 0}, cells, version)));
    pub.spin_once(Stamp::now());
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  std::istringstream r(reader.expect("result").substr(7));
  Latency l;
  std::uint64_t bad = 0;
  double secs = 0;
  double cpu = 0;
  r >> l.samples >> secs >> bad >> cpu >> l.p50_us >> l.p99_us >> l.max_us;
  return l;
}

// ddsperf's sample rate at the same payload size, same XML, same machine, same run: the median
// of its per-second receive rates while the publisher runs.
double ddsperf_rate(int domain, std::size_t size, double seconds, const std::string& qos) {
  const int dur = static_cast<int>(seconds + 0.5);
  Pipe sub("ddsperf -i " + std::to_string(domain) + " -D " + std::to_string(dur + 2) + qos +
           " sub 2>&1");
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  const std::string pub = "ddsperf -i " + std::to_string(domain) + " -D " + std::to_string(dur) +
                          qos + " pub size " + std::to_string(size) + " > /dev/null 2>&1";
  if (std::system(pub.c_str()) != 0) throw std::runtime_error("ddsperf pub failed");
  std::vector<double> rates;
  std::string l;
  while (sub.line(l)) {
    const auto at = l.find(" rate ");
    if (l.find(" size ") == std::string::npos || at == std::string::npos) continue;
    const double kS = std::strtod(l.c_str() + at + 6, nullptr);
    if (kS > 0) rates.push_back(kS * 1e3);
  }
  if (rates.size() > 2) rates.erase(rates.begin());  // ramp-up second
  if (rates.empty()) return 0;
  std::sort(rates.begin(), rates.end());
  return rates[rates.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  try {
    // Pin DDS to loopback unless the caller chose a configuration.
    setenv("CYCLONEDDS_URI", "file://" SEMAP_DDS_LOOPBACK_XML, 0);
    if (argc == 6 && std::strcmp(argv[1], "--reader") == 0) {
      return std::strcmp(argv[4], "1") == 0
                 ? run_latency_reader(std::atoi(argv[2]), argv[3])
                 : run_client_reader(std::atoi(argv[2]), argv[3], argv[5]);
    }
    std::random_device rd;
    const int domain = 1 + static_cast<int>(rd() % 200);
    if (argc >= 4 && argc <= 6 && std::strcmp(argv[1], "--throughput") == 0) {
      const auto cells = static_cast<std::uint16_t>(std::atoi(argv[2]));
      const double rate = argc >= 5 ? std::atof(argv[4]) : 0.0;
      const Throughput t =
          throughput(domain, cells, std::atof(argv[3]), rate, argc == 6 ? argv[5] : "waitset");
      std::printf("%u^3 cells: written %.0f/s received %.0f/s (%llu blocks, %llu invalid)\n", cells,
                  t.written_per_s, t.blocks_per_s, static_cast<unsigned long long>(t.received),
                  static_cast<unsigned long long>(t.bad));
      std::printf(
          "CPU per block: writer %.1f us, reader %.1f us; writing thread busy %.0f %% of the"
          " time; write timeouts %llu\n",
          t.writer_cpu_us, t.reader_cpu_us, 100.0 * t.writer_thread_busy,
          static_cast<unsigned long long>(t.write_timeouts));
      std::printf("writing thread context switches: %lld voluntary, %lld involuntary\n",
                  static_cast<long long>(t.writer_voluntary_switches),
                  static_cast<long long>(t.writer_involuntary_switches));
      return 0;
    }
    const double seconds = argc > 1 ? std::atof(argv[1]) : 3.0;
    const int reps = argc > 2 ? std::max(1, std::atoi(argv[2])) : 3;
    std::printf("dds_bench: domain %d, CYCLONEDDS_URI=%s, %.0f s a run, median of %d\n", domain,
                std::getenv("CYCLONEDDS_URI"), seconds, reps);
    // ddsperf twice: its default (reliable keep-all, one key: the baseline) and with
    // our map QoS (keep-last 1 over 1000 keys), which cannot throttle the writer. Our reader, a
    // MapClient, twice: taking on Cyclone's receive thread (take_on_receive), as ddsperf's
    // subscriber does by default, and by poll() from a thread woken by a waitset.
    std::printf("%-26s %10s %8s %10s %14s %6s %16s %6s\n", "map blocks (no evidence)", "blocks/s",
                "MB/s", "written/s", "ddsperf dflt/s", "ratio", "ddsperf k1 n1000", "ratio");
    // Interleaved repetitions, medians reported: load from other processes comes and goes.
    const auto median = [](std::vector<double> v) {
      std::sort(v.begin(), v.end());
      return v[v.size() / 2];
    };
    for (std::uint16_t cells : {5, 8}) {
      const std::size_t bytes = block_bytes(cells);
      struct Series {
        std::vector<double> received, mbs, written, wcpu, rcpu;
        std::uint64_t bad = 0;
        void add(const Throughput& t) {
          received.push_back(t.blocks_per_s);
          mbs.push_back(t.mb_per_s);
          written.push_back(t.written_per_s);
          wcpu.push_back(t.writer_cpu_us);
          rcpu.push_back(t.reader_cpu_us);
          bad += t.bad;
        }
      };
      Series listener, waitset;
      std::vector<double> ref, ref_k1;
      for (int rep = 0; rep < reps; ++rep) {
        listener.add(throughput(domain, cells, seconds, 0.0, "listener"));
        waitset.add(throughput(domain, cells, seconds, 0.0, "waitset"));
        ref.push_back(ddsperf_rate(domain, bytes, seconds, ""));
        ref_k1.push_back(ddsperf_rate(domain, bytes, seconds, " -k 1 -n 1000"));
      }
      const double r = median(ref), r1 = median(ref_k1);
      for (const auto& [name, series] : {std::pair{"listener", &listener}, {"waitset", &waitset}}) {
        const double o = median(series->received);
        char label[64];
        std::snprintf(label, sizeof label, "%u^3 cells, %zu B, %s", cells, bytes, name);
        std::printf("%-26s %10.0f %8.1f %10.0f %14.0f %5.0f%% %16.0f %5.0f%%%s\n", label, o,
                    median(series->mbs), median(series->written), r, r > 0 ? 100.0 * o / r : 0.0,
                    r1, r1 > 0 ? 100.0 * o / r1 : 0.0,
                    series->bad ? " (INVALID BLOCKS RECEIVED)" : "");
        std::printf("  CPU per block (all threads): writer %.1f us, reader %.1f us\n",
                    median(series->wcpu), median(series->rcpu));
      }
      std::fflush(stdout);
      // Both reader modes: the waitset one is how MapClient::poll takes.
      for (const char* mode : {"listener", "waitset"}) {
        const Matched m = matched_rate(domain, cells, seconds, r, mode);
        std::printf(
            "  matched rate (%s, writer paced, >= 99 %% taken): %.0f blocks/s, %.0f%% of"
            " ddsperf default; CPU per block writer %.1f us, reader %.1f us\n",
            mode, m.blocks_per_s, r > 0 ? 100.0 * m.blocks_per_s / r : 0.0, m.writer_cpu_us,
            m.reader_cpu_us);
        std::fflush(stdout);
      }
    }
    for (int per_update : {10, 100}) {
      const Latency l = latency(domain, 8, per_update, std::max(3.0, seconds));
      std::printf(
          "latency, 10 Hz x %3d changed 8^3 blocks: p50 %6.0f us  p99 %6.0f us  max %6.0f us"
          " (%llu blocks)\n",
          per_update, l.p50_us, l.p99_us, l.max_us, static_cast<unsigned long long>(l.samples));
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "dds_bench: %s\n", e.what());
    return 1;
  }
  return 0;
}

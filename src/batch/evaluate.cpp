#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <map>
#include <mutex>
#include <optional>
#include <sstream>
#include <thread>

#include <tubeplan/batch/evaluate.hpp>
#include <tubeplan/io/interrupt.hpp>
#include <tubeplan/io/trajectory_csv.hpp>
#include <tubeplan/trajectories/perturb.hpp>

namespace tubeplan::batch {

namespace {

// FNV-1a of the plan's path: each plan's replicates depend on the seed and the plan only, not on
// which shard or thread judges it.
std::uint64_t PlanSeed(std::uint64_t seed, const std::string& file) {
  std::uint64_t h = 1469598103934665603ull ^ seed;
  for (unsigned char c : file) h = (h ^ c) * 1099511628211ull;
  return h;
}

// One plan judged, with its replicates; nothing when a signal cut its replicates short.
std::optional<Evaluated> JudgePlan(const std::string& file, const io::PlanLoadResult& l,
                                   const BatchOptions& options, std::size_t i) {
  const plan::TickWatcher watch = options.watch ? options.watch(i) : plan::TickWatcher{};
  std::optional<plan::Judgement> judgement;
  if (l.trajectory) {
    judgement = plan::Judge(*l.scene, *l.trajectory, l.plan->states, l.plan->limits, watch);
  } else {
    io::TrajectoryFileSamples samples(*l.trajectory_file);
    trajectories::SampleTicks ticks(samples, l.trajectory_file->t_first_s,
                                    l.trajectory_file->t_last_s, l.scene->model.time_step_s);
    judgement = plan::Judge(*l.scene, ticks, l.plan->states, l.plan->limits, watch,
                            l.trajectory_file->stopped_early);
  }
  Evaluated e{file, *l.plan, std::move(*judgement), 0, {}};
  e.runs = options.monte_carlo;
  e.robust.assign(e.judgement.transitions.size(), 0);
  e.replayed_s = e.judgement.replayed_s;
  e.run_s = e.judgement.run_s;
  for (int r = 0; r < options.monte_carlo && !io::Interrupted(); ++r) {
    const plan::Judgement jr =
        plan::Judge(*l.scene,
                    trajectories::Perturb(*l.trajectory, trajectories::Perturbation{},
                                          PlanSeed(options.seed, file), r),
                    l.plan->states, l.plan->limits);
    for (std::size_t k = 0; k < jr.transitions.size(); ++k)
      e.robust[k] += plan::IsFeasible(jr.transitions[k].verdict);
    e.replayed_s += jr.replayed_s;
    e.run_s += jr.run_s;
  }
  if (io::Interrupted()) return std::nullopt;  // a Monte Carlo series cut short is not a result
  return e;
}

}  // namespace

std::string CanonicalPlanPath(const std::string& path) {
  std::error_code ec;
  const std::filesystem::path absolute = std::filesystem::absolute(path, ec);
  const std::filesystem::path canonical = std::filesystem::weakly_canonical(absolute, ec);
  return (ec ? absolute.lexically_normal() : canonical).string();
}

std::string PlanSetId(std::vector<std::string> canonical_paths) {
  std::sort(canonical_paths.begin(), canonical_paths.end());
  std::uint64_t h = 1469598103934665603ull;
  for (const std::string& path : canonical_paths) {
    for (const unsigned char c : path) h = (h ^ c) * 1099511628211ull;
    h = (h ^ static_cast<unsigned char>('\n')) * 1099511628211ull;
  }
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h));
  return hex;
}

PlanSet CollectPlanSet(const std::vector<std::string>& inputs, std::vector<std::string>& errors) {
  namespace fs = std::filesystem;
  std::vector<std::string> named;
  for (const std::string& input : inputs) {
    std::error_code ec;
    if (!fs::is_directory(input, ec)) {
      named.push_back(input);
      continue;
    }
    std::vector<std::string> in_dir;
    for (const fs::directory_entry& e : fs::directory_iterator(input, ec))
      if (e.is_regular_file() && e.path().extension() == ".yaml")
        in_dir.push_back(e.path().string());
    std::sort(in_dir.begin(), in_dir.end());
    if (in_dir.empty())
      errors.push_back(input + ": error: no plan files (*.yaml) in this directory, expected plans");
    named.insert(named.end(), in_dir.begin(), in_dir.end());
  }
  std::map<std::string, std::string> by_canonical;  // canonical path -> as first given
  for (const std::string& f : named) by_canonical.emplace(CanonicalPlanPath(f), f);
  PlanSet set;
  for (const auto& [path, given] : by_canonical) {
    set.canonical.push_back(path);
    set.files.push_back(given);
  }
  set.id = PlanSetId(set.canonical);
  set.size = static_cast<long>(set.files.size());
  return set;
}

bool SelectShard(const std::string& text, PlanSet& set, std::string& error) {
  int index = 0, count = 0;
  char slash = 0, extra = 0;
  std::istringstream in(text);
  if (!(in >> index >> slash >> count) || slash != '/' || in >> extra || count < 1 || index < 1 ||
      index > count) {
    error = "--shard \"" + text + "\" is not a shard, expected I/N with 1 <= I <= N, e.g. 2/8";
    return false;
  }
  PlanSet mine = set;
  mine.files.clear();
  mine.canonical.clear();
  for (std::size_t i = 0; i < set.files.size(); ++i) {
    if (static_cast<int>(i % std::size_t(count)) != index - 1) continue;
    mine.files.push_back(set.files[i]);
    mine.canonical.push_back(set.canonical[i]);
  }
  mine.shard_index = index;
  mine.shard_count = count;
  set = std::move(mine);
  return true;
}

BatchResult JudgeBatch(const std::vector<std::string>& files,
                       const std::vector<io::PlanLoadResult>& loaded, const BatchOptions& options) {
  BatchResult batch;
  batch.results.resize(files.size());
  std::atomic<std::size_t> next{0}, judged{0};
  std::mutex changed_mutex;
  auto work = [&] {
    for (std::size_t i = next++; i < files.size() && !io::Interrupted(); i = next++) {
      try {
        std::optional<Evaluated> e = JudgePlan(files[i], loaded[i], options, i);
        if (!e) break;
        batch.results[i] = std::move(*e);
      } catch (const io::InputChanged& changed) {
        const std::lock_guard lock(changed_mutex);
        batch.changed.emplace_back(changed.what());
        continue;
      }
      const std::size_t count = ++judged;
      if (options.judged) options.judged(count);
    }
  };
  const auto clock_start = std::chrono::steady_clock::now();
  const int jobs = std::clamp(options.jobs, 1, std::max(1, static_cast<int>(files.size())));
  std::vector<std::thread> threads;
  for (int w = 1; w < jobs; ++w) threads.emplace_back(work);
  work();
  for (std::thread& t : threads) t.join();
  batch.wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - clock_start).count();
  batch.judged = judged.load();
  return batch;
}

}  // namespace tubeplan::batch

// The HTML report (evaluate --html): the page's series are the judged replay's own ticks,
// decimated without losing a peak; the page is self-contained. (The page in a browser:
// tools/report-web/browser-test.mjs, registered with ctest as html_report_browser.)
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <regex>
#include <sstream>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <tubeplan/io/mesh_file.hpp>
#include <tubeplan/io/plan_file.hpp>
#include <tubeplan/plan/judge.hpp>
#include <tubeplan/report/html_report.hpp>

#include "run_tool.hpp"

namespace {

using namespace tubeplan;
using testing::RunTool;
using testing::Slurp;
using testing::SourcePath;

std::filesystem::path TempDir(const std::string& name) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

}  // namespace

TEST_CASE("The report's series are the judged replay's ticks, each bin's extremes kept",
          "[cli][html]") {
  // The gentle plan: the operator force crosses its 0.2 N limit, so peaks matter.
  const io::PlanLoadResult l = io::LoadPlanFile(SourcePath("plans/groove-gentle.yaml"));
  REQUIRE(l.plan);
  std::vector<double> t_s, force_N, energy_J;
  const plan::Judgement plain =
      plan::Judge(*l.scene, *l.trajectory, l.plan->states, l.plan->limits);
  report::ReplayRecorder recorder;
  const plan::Judgement watched =
      plan::Judge(*l.scene, *l.trajectory, l.plan->states, l.plan->limits,
                  [&](double t, const core::Core& core) {
                    recorder(t, core);
                    t_s.push_back(t);
                    force_N.push_back(core.last().force_W_N.norm());
                    energy_J.push_back(core.last().energy_J);
                  });
  const report::ReplayRecording r = recorder.Finish();

  // Watching changes nothing the judge decides.
  REQUIRE(plain.transitions.size() == watched.transitions.size());
  for (std::size_t k = 0; k < plain.transitions.size(); ++k) {
    CHECK(plain.transitions[k].verdict == watched.transitions[k].verdict);
    CHECK(plain.transitions[k].reason == watched.transitions[k].reason);
    CHECK(plain.transitions[k].peak_force_N == watched.transitions[k].peak_force_N);
  }
  CHECK(plain.observed.size() == watched.observed.size());
  // Every tick seen once.
  CHECK(long(t_s.size()) == watched.ticks);

  // Bins of 20 ms: each bin's minimum and maximum are exactly the extremes of its ticks (a
  // one-tick spike survives), and one 3D frame per bin, its first tick, and the peak's frame.
  REQUIRE(!r.bins.empty());
  CHECK(r.bin_s == 0.02);
  CHECK((r.frames.size() == r.bins.size() || r.frames.size() == r.bins.size() + 1));
  REQUIRE(r.peak_frame < r.frames.size());
  const double peak_N = *std::max_element(force_N.begin(), force_N.end());
  CHECK(r.frames[r.peak_frame].force_N == peak_N);
  CHECK(r.frames[r.peak_frame].t_s ==
        t_s[std::size_t(std::max_element(force_N.begin(), force_N.end()) - force_N.begin())]);
  // The judge's peak of the whole replay is the same figure.
  CHECK(watched.peak_force_N == peak_N);
  std::vector<double> lo(r.bins.size(), 1e300), hi(r.bins.size(), -1e300), e_hi = hi;
  for (std::size_t k = 0; k < t_s.size(); ++k) {
    const auto b = std::size_t(std::floor((t_s[k] - t_s.front()) / r.bin_s));
    REQUIRE(b < r.bins.size());
    lo[b] = std::min(lo[b], force_N[k]);
    hi[b] = std::max(hi[b], force_N[k]);
    e_hi[b] = std::max(e_hi[b], energy_J[k]);
  }
  for (std::size_t b = 0; b < r.bins.size(); ++b) {
    CHECK(r.bins[b].force_N.min == lo[b]);
    CHECK(r.bins[b].force_N.max == hi[b]);
    CHECK(r.bins[b].energy_J.max == e_hi[b]);
  }
  // The overall peak is at least the judge's peak of every transition (the judge stops counting
  // after the plan fails; the recording does not).
  double peak = 0.0;
  for (const auto& b : r.bins) peak = std::max(peak, b.force_N.max);
  for (const auto& v : watched.transitions) CHECK(peak >= v.peak_force_N);
  CHECK(peak == *std::max_element(force_N.begin(), force_N.end()));
  // The frames' shapes are the core's centreline: the held end first, the tube's length along it.
  for (const auto& f : r.frames) {
    double length = 0.0;
    for (std::size_t i = 1; i < f.centreline_W_m.size(); ++i)
      length += (f.centreline_W_m[i] - f.centreline_W_m[i - 1]).norm();
    // A chord polygon of 24 points is shorter than the arc, by far less than 1 % here.
    CHECK(length == Approx(l.scene->tube.length_m).epsilon(0.01));
    CHECK((f.centreline_W_m.front() - f.p_WH_m).norm() < 1e-6);
  }
}

TEST_CASE("A long replay's recording stays bounded, each bin's extremes kept", "[cli][html]") {
  // At most 16 bins here (2048 on a page): the 5.5 s replay's 275 bins of 20 ms become 9 bins of
  // 640 ms (halved five times), each still with the exact extremes of its ticks and one frame,
  // its first tick.
  const io::PlanLoadResult l = io::LoadPlanFile(SourcePath("plans/groove-gentle.yaml"));
  REQUIRE(l.plan);
  std::vector<double> t_s, force_N, strain;
  report::ReplayRecorder recorder(0.02, 16);
  plan::Judge(*l.scene, *l.trajectory, l.plan->states, l.plan->limits,
              [&](double t, const core::Core& core) {
                recorder(t, core);
                t_s.push_back(t);
                force_N.push_back(core.last().force_W_N.norm());
                strain.push_back(core.last().max_strain);
              });
  const report::ReplayRecording r = recorder.Finish();
  CHECK(r.bin_s == Approx(0.64));
  REQUIRE(r.bins.size() == 9);
  std::vector<double> lo(r.bins.size(), 1e300), hi(r.bins.size(), -1e300), s_hi = hi;
  std::vector<double> first(r.bins.size(), -1.0);
  for (std::size_t k = 0; k < t_s.size(); ++k) {
    const auto b = std::size_t(std::floor((t_s[k] - t_s.front()) / r.bin_s));
    REQUIRE(b < r.bins.size());
    lo[b] = std::min(lo[b], force_N[k]);
    hi[b] = std::max(hi[b], force_N[k]);
    s_hi[b] = std::max(s_hi[b], strain[k]);
    if (first[b] < 0.0) first[b] = t_s[k];
  }
  for (std::size_t b = 0; b < r.bins.size(); ++b) {
    CHECK(r.bins[b].force_N.min == lo[b]);
    CHECK(r.bins[b].force_N.max == hi[b]);
    CHECK(r.bins[b].strain.max == s_hi[b]);
  }
  // One frame per bin at its first tick, and the peak's.
  std::vector<double> frame_t;
  for (std::size_t i = 0; i < r.frames.size(); ++i)
    if (i != r.peak_frame) frame_t.push_back(r.frames[i].t_s);
  CHECK(frame_t == first);
  CHECK(r.frames[r.peak_frame].force_N == *std::max_element(force_N.begin(), force_N.end()));
  for (std::size_t i = 1; i < r.frames.size(); ++i) CHECK(r.frames[i - 1].t_s < r.frames[i].t_s);
}

TEST_CASE("evaluate --html of a long recording: a bounded page", "[cli][html]") {
  // Two minutes of the hand in free space above the groove at 1 kHz (as
  // tools/make-long-trajectory writes): 6000 bins of 20 ms, kept to at most 2048 on the page.
  const std::filesystem::path dir = TempDir("tubeplan-html-long");
  {
    std::ofstream csv(dir / "long.csv");
    csv << "t,px,py,pz,qw,qx,qy,qz\n";
    for (int i = 0; i <= 120000; ++i) {
      const double t = i / 1000.0, roll = -std::numbers::pi / 2 + 0.087 * std::sin(t);
      csv << t << "," << 0.005 * std::sin(t / 2) << ",-0.09,0.04," << std::cos(roll / 2) << ","
          << std::sin(roll / 2) << ",0,0\n";
    }
    std::ofstream(dir / "long.yaml")
        << "tubeplan: 1\nplan: long\nscene: " << SourcePath("scenes/groove.yaml")
        << "\ntrajectory: long.csv\nstates: [\"{}\", goal]\n";
  }
  const std::string html = (dir / "report.html").string();
  const testing::Outcome r = RunTool({"evaluate", (dir / "long.yaml").string(), "--html", html});
  INFO(r.err);
  REQUIRE(r.exit_code == 1);  // never reaches the goal
  const std::string page = Slurp(html);
  const std::size_t start = page.find("<script type=\"application/json\" id=\"tubeplan-data\">");
  REQUIRE(start != std::string::npos);
  const std::size_t body = page.find('>', start) + 1;
  const nlohmann::json data =
      nlohmann::json::parse(page.substr(body, page.find("</script>", body) - body));
  const nlohmann::json& frames = data["plans"][0]["frames"];
  CHECK(frames["t_s"].size() <= report::ReplayRecording::kMaxBins + 1);
  CHECK(frames["t_s"].size() > report::ReplayRecording::kMaxBins / 2);
  CHECK(data["plans"][0]["bin_s"] == 0.08);
  // The page: three.js (0.6 MB), the frames and the plots, the bins bounded.
  CHECK(page.size() < 2'000'000);
  std::filesystem::remove_all(dir);
}

TEST_CASE("evaluate --html writes one self-contained page with every plan", "[cli][html]") {
  const std::filesystem::path dir = TempDir("tubeplan-html-test");
  const std::string html = (dir / "report.html").string();
  const testing::Outcome r = RunTool({"evaluate", SourcePath("plans/groove-insert.yaml"),
                                      SourcePath("plans/groove-gentle.yaml"), "--html", html});
  INFO(r.err);
  REQUIRE(r.exit_code == 1);  // the gentle plan is infeasible by design
  CHECK(r.out.find("HTML report written to " + html) != std::string::npos);
  const std::string page = Slurp(html);
  CHECK(page.rfind("<!DOCTYPE html>", 0) == 0);
  CHECK(page.find("</html>") != std::string::npos);
  // Nothing fetched from outside: no http(s) or protocol-relative src/href.
  const std::regex external(R"re((src|href)\s*=\s*["']?\s*(https?:)?//)re", std::regex::icase);
  CHECK(!std::regex_search(page, external));
  // three.js is in it (its licence header), with the page's script and the data.
  CHECK(page.find("Three.js Authors") != std::string::npos);
  CHECK(page.find("OrbitControls") != std::string::npos);
  const std::size_t start = page.find("<script type=\"application/json\" id=\"tubeplan-data\">");
  REQUIRE(start != std::string::npos);
  const std::size_t body = page.find('>', start) + 1;
  const nlohmann::json data =
      nlohmann::json::parse(page.substr(body, page.find("</script>", body) - body));
  REQUIRE(data["plans"].size() == 2);
  CHECK(data["tube_colour"] == report::kTubeColour);
  for (const nlohmann::json& p : data["plans"]) {
    const std::size_t frames = p["frames"]["t_s"].size();
    CHECK(frames > 200);  // 5.5 s at 50 Hz
    CHECK(p["frames"]["centreline_mm"].size() == frames);
    CHECK(p["frames"]["centreline_mm"][0].size() == 3 * report::ReplayRecording::kCentrelinePoints);
    CHECK(p["parts"].size() == 3);
    // The summary's peak force is the replay's peak, the frame the 3D view opens at.
    const std::size_t peak = p["peak_frame"];
    const std::vector<double> forces = p["frames"]["force_abs_N"];
    CHECK(forces[peak] == *std::max_element(forces.begin(), forces.end()));
    char figure[32];
    std::snprintf(figure, sizeof figure, "%.3f", forces[peak]);
    const std::size_t row = page.find(">" + p["name"].get<std::string>() + "</a></td>");
    REQUIRE(row != std::string::npos);
    const std::size_t row_end = page.find("</tr>", row);
    CHECK(page.substr(row, row_end - row)
              .find("<td class=\"num\">" + std::string(figure) + "</td>") != std::string::npos);
  }
  // The verdicts, the timeline, four plots a plan; the gentle plan's force over its 0.05 N limit
  // is marked (a span and a peak marker) on its force plot.
  CHECK(page.find("limit 0.050 N") != std::string::npos);
  CHECK(page.find("class=\"marker\"") != std::string::npos);
  CHECK(page.find("planned transitions") != std::string::npos);
  CHECK(page.find("--html-graph") != std::string::npos);  // the note on how to add the graph
  std::filesystem::remove_all(dir);
}

TEST_CASE("The page carries a mesh part's surface once, in its frame, in millimetres",
          "[cli][html]") {
  // The groove plan judged, then drawn on its scene with two parts of the clip's mesh, and again
  // on a copy holding the clip loaded a second time: the page keeps one mesh, every part
  // pointing at it with its own pose.
  const io::PlanLoadResult l = io::LoadPlanFile(SourcePath("plans/groove-insert.yaml"));
  REQUIRE(l.plan);
  report::ReplayRecorder recorder;
  batch::Evaluated e;
  e.file = "plans/groove-insert.yaml";
  e.plan = *l.plan;
  e.judgement = plan::Judge(*l.scene, *l.trajectory, l.plan->states, l.plan->limits,
                            [&](double t, const core::Core& core) { recorder(t, core); });
  const auto load_clip = [] {
    io::MeshLoadResult clip = io::LoadMeshFile(SourcePath("scenes/clip.obj"), 1e-3);
    REQUIRE(clip.mesh);
    return scene::MakePartMesh("clip.obj", std::move(*clip.mesh), std::move(*clip.elements));
  };
  const std::shared_ptr<const scene::PartMesh> clip = load_clip(), clip_again = load_clip();
  Eigen::Isometry3d X_WP = Eigen::Isometry3d::Identity();
  X_WP.translation() = Eigen::Vector3d(0.05, 0.02, 0.01);
  X_WP.linear() = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  scene::Scene with_clips = *l.scene, with_clip_again = *l.scene;
  with_clips.parts.push_back(scene::MakeMeshPart("clip_a", clip, X_WP));
  with_clips.parts.push_back(scene::MakeMeshPart("clip_b", clip, Eigen::Isometry3d::Identity()));
  with_clip_again.parts.push_back(scene::MakeMeshPart("clip_c", clip_again, X_WP));
  const report::ReplayRecording r = recorder.Finish();
  const std::vector<report::HtmlPlan> plans = {{&e, &with_clips, "groove.yaml", r},
                                               {&e, &with_clip_again, "groove.yaml", r}};
  const std::string page = report::FormatHtmlReport(plans, {});
  const std::size_t start = page.find("<script type=\"application/json\" id=\"tubeplan-data\">");
  REQUIRE(start != std::string::npos);
  const std::size_t body = page.find('>', start) + 1;
  const nlohmann::json data =
      nlohmann::json::parse(page.substr(body, page.find("</script>", body) - body));

  REQUIRE(data["meshes"].size() == 1);
  const nlohmann::json& m = data["meshes"][0];
  const std::size_t vertices = clip->mesh.vertices_P_m.size();
  const std::size_t triangles = clip->mesh.triangles.size();
  CHECK(triangles > 100);  // the clip's tessellated arcs
  CHECK(m["vertices_mm"].size() == 3 * vertices);
  CHECK(m["triangles"].size() == 3 * triangles);
  std::size_t segments = 0;
  for (const scene::MeshEdge& edge : clip->elements.edges) segments += edge.segments.size();
  CHECK(segments > 0);
  CHECK(m["edges"].size() == 2 * segments);
  // Vertices in the part's frame in millimetres, to the page's 0.01 mm; indices as the mesh's.
  for (std::size_t i = 0; i < vertices; ++i)
    for (int c = 0; c < 3; ++c)
      // Half the 0.01 mm rounding step, and the rounding of the printed double.
      CHECK(m["vertices_mm"][3 * i + std::size_t(c)].get<double>() ==
            Approx(clip->mesh.vertices_P_m[i][c] * 1e3).margin(0.005 + 1e-9));
  for (std::size_t t = 0; t < triangles; ++t)
    for (int k = 0; k < 3; ++k)
      CHECK(m["triangles"][3 * t + std::size_t(k)] == clip->mesh.triangles[t][std::size_t(k)]);

  // Each mesh part names the mesh and carries its own pose; the boxes stay boxes.
  REQUIRE(data["plans"].size() == 2);
  for (std::size_t k = 0; k < 2; ++k) {
    const nlohmann::json& p = data["plans"][k];
    REQUIRE(p["parts"].size() == l.scene->parts.size() + (k == 0 ? 2 : 1));
    for (std::size_t i = 0; i < l.scene->parts.size(); ++i) {
      CHECK(p["parts"][i]["shape"] == "box");
      CHECK(!p["parts"][i].contains("mesh"));
    }
    const nlohmann::json& clip_part = p["parts"][l.scene->parts.size()];
    CHECK(clip_part["shape"] == "mesh");
    CHECK(clip_part["mesh"] == 0);
    CHECK(clip_part["p_mm"] == nlohmann::json({50.0, 20.0, 10.0}));
    // q = (cos 0.15, 0, 0, sin 0.15), to the page's 1e-6.
    CHECK(clip_part["q_wxyz"][0].get<double>() == Approx(std::cos(0.15)).margin(1e-6));
    CHECK(clip_part["q_wxyz"][3].get<double>() == Approx(std::sin(0.15)).margin(1e-6));
  }
  CHECK(data["plans"][0]["parts"][l.scene->parts.size() + 1]["mesh"] == 0);
}

TEST_CASE("evaluate: --html-graph needs --html", "[cli][html]") {
  const testing::Outcome r =
      RunTool({"evaluate", SourcePath("plans/groove-insert.yaml"), "--html-graph"});
  CHECK(r.exit_code == 2);
  CHECK(r.err.find("--html-graph needs --html FILE") != std::string::npos);
}

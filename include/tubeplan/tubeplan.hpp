#pragma once
// tubeplan as a library: everything a program calls to do what the commands do. Load a scene
// and a plan (io), step the core with a hand pose (core), judge a plan's replay or sum up a
// trajectory's (plan), judge a set of plans and replay a trajectory file (batch), explore and
// prune the contact-state graph (graph; batch as the commands do it), make candidate plans
// (plan) and write them (batch), make a hand trajectory through poses or perturb one
// (trajectories), run the 1 kHz servo against a device (device), write the reports of judged
// plans and of the graph (report). Each header says what it holds; docs/layout.md says which
// library each folder is.

#include <tubeplan/batch/evaluate.hpp>
#include <tubeplan/batch/evaluation.hpp>
#include <tubeplan/batch/graph.hpp>
#include <tubeplan/batch/merge.hpp>
#include <tubeplan/batch/plans.hpp>
#include <tubeplan/batch/report.hpp>
#include <tubeplan/batch/simulation.hpp>
#include <tubeplan/core/core.hpp>
#include <tubeplan/device/device.hpp>
#include <tubeplan/device/device_choice.hpp>
#include <tubeplan/device/host_check.hpp>
#include <tubeplan/device/servo.hpp>
#include <tubeplan/graph/completeness.hpp>
#include <tubeplan/graph/dot.hpp>
#include <tubeplan/graph/explore.hpp>
#include <tubeplan/graph/paths.hpp>
#include <tubeplan/io/plan_file.hpp>
#include <tubeplan/io/scene_yaml.hpp>
#include <tubeplan/io/trajectory_csv.hpp>
#include <tubeplan/live/live_run.hpp>
#include <tubeplan/plan/candidates.hpp>
#include <tubeplan/plan/judge.hpp>
#include <tubeplan/plan/simulate.hpp>
#include <tubeplan/report/graph_json.hpp>
#include <tubeplan/report/html_report.hpp>
#include <tubeplan/report/text_report.hpp>
#include <tubeplan/scene/scene.hpp>
#include <tubeplan/states/contact_formation.hpp>
#include <tubeplan/trajectories/perturb.hpp>
#include <tubeplan/trajectories/synthesize.hpp>
#include <tubeplan/trajectories/trajectory.hpp>

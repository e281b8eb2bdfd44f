#pragma once
// The accuracy study as `tubeplan accuracy` prints it (docs/accuracy.md): the reference rod's
// convergence and a row per setting and scenario as text, the whole study as one JSON document,
// and the error-vs-time chart as SVG.

#include <ostream>
#include <string>

#include <nlohmann/json.hpp>

#include <tubeplan/study/accuracy.hpp>

namespace tubeplan::report {

/// The study as one JSON document: scene, elements, rows, references (tip loads, contact
/// scenarios, convergence) and notes; errors and times that are not finite are null.
nlohmann::json AccuracyJson(const study::AccuracyReport& study);

/// The study as text: the reference rod's convergence, the table of rows, a legend and the notes.
void PrintAccuracy(std::ostream& out, const study::AccuracyReport& study);

/// The chart as one SVG document: a marker per setting, its worst error over the contact
/// scenarios against its mean tick time, against the same contact law and against hard contact.
std::string AccuracySvg(const study::AccuracyReport& study);

}  // namespace tubeplan::report

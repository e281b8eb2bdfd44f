#pragma once
// Joining the reports of a sharded evaluation (`tubeplan evaluate --shard I/N --report`) into
// the report one unsharded run gives (docs/evaluate.md, "Sharding").

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace tubeplan::batch {

/// The report of the whole plan set from the reports at `paths`, which must be shards 1..N of
/// one plan set, each once, holding every plan of it once; or nullopt with every problem found
/// in `errors`, each a line "path: error: what, expected what".
std::optional<nlohmann::json> MergeShardReports(const std::vector<std::string>& paths,
                                                std::vector<std::string>& errors);

}  // namespace tubeplan::batch

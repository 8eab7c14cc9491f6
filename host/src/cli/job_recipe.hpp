// How `stream` plans a job again after a host crash: the drawing's bytes kept beside the
// journal, the path options as the stream used them, where a lead-in started, and hashes that
// show nothing changed since (docs/cli.md, "Interrupt and resume").
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "path_options.hpp"

namespace pathstream::host {

/// What the journal's "replan" object holds.
struct JobRecipe {
    JobRequest path;  ///< file: the drawing's copy; format: the format it was read as
    std::optional<std::vector<double>> lead_in_from;  ///< mm per axis: --lead-in's start
    std::string input_hash;                           ///< content_hash of the copy
    std::string machine_hash;  ///< content_hash of the machine profile's file
    std::string planner;       ///< the program that planned it ("pathstream 0.1.0")
};

/// The planner's name and version, as recipes record it.
const char* planner_identity();

/// Copies the drawing `path.file` names (standard input for "-") to `copy` atomically and
/// returns the recipe for it: `path` with file = `copy` and the format it was read as, and the
/// hashes of the copy and of `machine_file`. When `path.file` is "-", `path` itself is pointed
/// at the copy (standard input can be read once). Throws InputError for an unreadable drawing
/// or profile, std::runtime_error when the copy cannot be written.
JobRecipe save_job_recipe(JobRequest& path, const std::string& machine_file,
                          const std::optional<std::vector<double>>& lead_in_from,
                          const std::string& copy);

/// The recipe as the journal's JSON object (compact text), and back. parse_job_recipe throws
/// InputError naming `journal` for a recipe with missing or mistyped keys.
std::string job_recipe_json(const JobRecipe& recipe);
JobRecipe parse_job_recipe(const std::string& json, const std::string& journal);

/// The content hash of a file's bytes; throws InputError when it cannot be read.
std::string file_content_hash(const std::string& file);

}  // namespace pathstream::host

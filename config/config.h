// The configuration of OpenABLE's programs: the option structs of every module that a
// Config.txt key sets, gathered in Config, and the one table that binds each key to its field
// (ConfigTable). That table drives reading Config.txt, the `--set Key=Value` overrides,
// `--help` and the configuration reference in docs/configuration.md. Key names and meanings
// are those of the original OpenABLE (Arroyo et al., ITSC 2016, and its Config.txt), so an old
// configuration runs unchanged; keys marked "new" are additions documented in the reference.
#pragma once

#include <string>
#include <vector>

#include "OpenABLE/image/preprocess.h"
#include "OpenABLE/odometry/options.h"
#include "OpenABLE/snaps/options.h"
#include "OpenABLE/verification/verification.h"
#include "config/option_table.h"
#include "config/run_options.h"
#include "descriptors/descriptor.h"
#include "descriptors/frame_describer.h"
#include "matching/matrix.h"

namespace openable {

// Every key's field, in the option struct of the module that uses it.
struct Config {
  InputOptions input;                  // Datasets, Camera_type
  OutputOptions output;                // Representation
  DescriptorOptions descriptor;        // Image_descriptor, Patch_size, Ldb_bits
  DescriptionOptions description;      // Description_type, Grid_x, Grid_y, Panoramas
  PreprocessOptions preprocess;        // Illumination_invariance, Alpha, Lambda_*, Robustness
  MatchingOptions matching;            // Image_sequences, Sequence_direction, Panorama_matching,
                                       // Threshold, Threads
  AutoOptions automatic;               // Auto
  ScaleOptions scale;                  // Scale
  EvaluationConfig evaluation;         // Evaluation
  VerificationOptions verification;    // Verification
  snaps::SnapsOptions snaps;           // SNAPS (openable_snaps)
  odometry::OdometryOptions odometry;  // Odometry and Snaps_odometry (openable_snaps)

  bool operator==(const Config& other) const;
  bool operator!=(const Config& other) const { return !(*this == other); }
};

// The one table of keys, bound to the fields of `config` (which must outlive it). Order =
// order in --help, in FormatConfig and in docs/configuration.md.
OptionTable ConfigTable(Config& config);

// Reads a configuration file: the flat "Key: value" subset of YAML that the original's
// OpenCV FileStorage files use ("%YAML:1.0" first line optional, '#' comments, strings quoted
// or not). Keys not present keep their defaults. Throws InputError with one line
// "<file>:<line>: <Key>: <problem>" on a missing or unreadable file, a line that is not
// "Key: value", an unknown key (naming the nearest valid one), a duplicated key, or a value
// of the wrong type or out of range.
Config LoadConfig(const std::string& path);
// The same over `base`: the keys the file gives replace those of `base`, the others are kept.
Config LoadConfig(const std::string& path, Config base);

// The parser of LoadConfig on the text of a configuration already in memory; `name` stands
// for the file in messages ("<name>:<line>: ..."). Same checks, same InputError messages.
Config ParseConfigText(const std::string& text, const std::string& name);

// Applies one "Key=Value" override (from --set; `where` names the option in messages). Same
// checks and messages as LoadConfig.
void ApplyOverride(Config& config, const std::string& assignment,
                   const std::string& where = "--set");

// What a run of Test_OpenABLE needs, checked before any work: the Check() of every struct it
// uses, then the rules across structs (D-LDB needs a stereo camera, a stereo camera describes
// grey images, ...). Throws InputError naming the key.
void CheckConfig(const Config& config);

// What openable_snaps needs: the SNAPS and odometry structs' Check(), a trajectory to correct
// (or odometry to compute it), the file a loop source reads, the images of the search, the
// calibration and folders of the odometry. Throws InputError naming the key, the value and
// what was expected.
void CheckSnapsConfig(const Config& config);

// The checks of CheckConfig on the Evaluation keys alone, for tools that only evaluate.
void CheckEvaluationConfig(const Config& config);

// Writes `config` in the same format LoadConfig reads (every key, with a comment each).
std::string FormatConfig(const Config& config);

// The keys for --help-keys: grouped, one entry per key with its meaning, default and range;
// only those of `group` when it is not empty (a group's name or its first word, any case).
// Throws InputError naming the groups for a group that is none of them.
std::string ConfigHelpText(const std::string& group = "");

// The groups of the keys, in the order of --help-keys ("Datasets", "Representation", ...).
std::vector<std::string> ConfigGroupNames();

// The same information as a Markdown table, for docs/configuration.md.
std::string ConfigMarkdownReference();

// The value of `key` as FormatConfig writes it (strings quoted). Throws std::logic_error for
// an unknown key.
std::string ConfigValueText(const Config& config, const std::string& key);

// Every key name, in table order.
std::vector<std::string> ConfigKeyNames();

}  // namespace openable

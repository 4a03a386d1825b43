// SPDX-License-Identifier: MIT
// What reproduces an experiment run: its name and its settings, named by the options' fields,
// which a front end writes in its own words (the command line: the command that reruns it).
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace tgraph::experiment {

/// One setting of a run, named by its options' field ("threads", "quick", "replay").
struct Setting {
  std::string field;
  std::optional<std::string> value;  ///< "1,2,4"; nullopt: a yes-or-no setting
  bool on = true;                    ///< a yes-or-no setting: on or off
};

/// A run as its settings: the experiment `experiment` with these options reproduces it.
///
///   {"metg", {{"quick"}, {"threads", "1,2"}, {"out", "m"}}}
struct Invocation {
  std::string experiment;  ///< "medical", "metg", "scaling" (run_named's names)
  std::vector<Setting> settings;
};

/// How the results files (results.json, the report's facts) write an invocation.
using InvocationWords = std::function<std::string(const Invocation&)>;

/// The words without a front end: "metg quick threads=1,2 out=m" (a setting that is off:
/// "replay=off").
std::string plain_words(const Invocation& invocation);
/// The words of a front end whose flags follow the fields: `program`, the experiment, then
/// each setting as flag(field) and its value, a setting that is off as flag("no_" + field)
/// (a front end whose `name` writes "quick" as "-Q" and "out" as "-O": "prog metg -Q -O m").
InvocationWords words_with(std::string program, std::function<std::string(std::string)> flag);
/// words(invocation), or plain_words(invocation) when `words` is empty.
std::string words_of(const InvocationWords& words, const Invocation& invocation);

}  // namespace tgraph::experiment

// SPDX-License-Identifier: MIT
// An experiment run's settings as words: plain ones, or a front end's.
#include "tgraph/experiment/settings.hpp"

namespace tgraph::experiment {

std::string plain_words(const Invocation& invocation) {
  std::string s = invocation.experiment;
  for (const Setting& x : invocation.settings) {
    s += " " + x.field;
    if (x.value)
      s += "=" + *x.value;
    else if (!x.on)
      s += "=off";
  }
  return s;
}

InvocationWords words_with(std::string program, std::function<std::string(std::string)> flag) {
  return [program, flag](const Invocation& invocation) {
    std::string s = program + " " + invocation.experiment;
    for (const Setting& x : invocation.settings)
      s += " " + flag(x.on ? x.field : "no_" + x.field) + (x.value ? " " + *x.value : "");
    return s;
  };
}

std::string words_of(const InvocationWords& words, const Invocation& invocation) {
  return words ? words(invocation) : plain_words(invocation);
}

}  // namespace tgraph::experiment

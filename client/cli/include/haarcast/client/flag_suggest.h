// "Did you mean": the nearest command or flag to a misspelt one, for the
// command lines built on CLI11 (`haarcast` and `haarcast-client`). CLI11
// says only "The following arguments were not expected: 64 --widht"; these
// name the word that is not a flag and the flag it most likely meant.
// Header-only: both binaries include it, the tests drive it with a CLI::App
// of their own (tests/unit/app/flag_suggest_test.cpp).
#pragma once

#include <algorithm>
#include <cctype>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace haarcast::cli {

// Edits from a to b: insertions, deletions, substitutions, and a swap of
// two neighbours ("widht" → "width") as one (optimal string alignment).
inline std::size_t editDistance(const std::string& a, const std::string& b) {
  std::vector<std::vector<std::size_t>> d(a.size() + 1, std::vector<std::size_t>(b.size() + 1));
  for (std::size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
  for (std::size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t cost = a[i - 1] == b[j - 1] ? 0 : 1;
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + cost});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1]) d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
    }
  }
  return d[a.size()][b.size()];
}

// The name nearest to `word`, if one is close enough to be a typo: at most
// 2 edits (1 for a word of 4 letters or fewer), the first of equals.
inline std::optional<std::string> nearestName(const std::string& word, const std::vector<std::string>& names) {
  const std::size_t most = word.size() <= 4 ? 1 : 2;
  std::optional<std::string> best;
  std::size_t bestDistance = most + 1;
  for (const std::string& name : names) {
    const std::size_t d = editDistance(word, name);
    if (d < bestDistance) {
      bestDistance = d;
      best = name;
    }
  }
  return best;
}

// Every flag `command` takes, as typed: "--width", "-k".
inline std::vector<std::string> flagNames(const CLI::App& command) {
  std::vector<std::string> names;
  for (const CLI::Option* o : command.get_options()) {
    for (const std::string& l : o->get_lnames()) names.push_back("--" + l);
    for (const std::string& s : o->get_snames()) names.push_back("-" + s);
  }
  return names;
}

// After CLI11 refused `args` (the words after the command's name) with
// "arguments were not expected": one line for each word that looks like a
// flag but names none of `command`'s, with the flag it most likely meant:
//   unknown flag --widht; did you mean --width?
// Values such as "-30,0,0" or "-1.5" are not flags; nothing after "--" is.
inline std::vector<std::string> unknownFlags(const CLI::App& command, const std::vector<std::string>& args) {
  const std::vector<std::string> names = flagNames(command);
  std::vector<std::string> lines;
  for (const std::string& arg : args) {
    if (arg == "--") break;
    const bool longFlag = arg.size() > 2 && arg.rfind("--", 0) == 0;
    const bool shortFlag = arg.size() == 2 && arg[0] == '-' && std::isalpha(static_cast<unsigned char>(arg[1]));
    if (!longFlag && !shortFlag) continue;
    const std::string flag = arg.substr(0, arg.find('='));
    if (std::find(names.begin(), names.end(), flag) != names.end()) continue;
    std::string line = "unknown flag " + flag;
    // A one-letter flag is one edit from every other: no guess for those.
    if (longFlag) {
      if (const auto near = nearestName(flag, names)) line += "; did you mean " + *near + "?";
    }
    lines.push_back(line);
  }
  return lines;
}

// The commands of `app` with their descriptions, one per line:
//   "  render           Render one frame …"
inline std::string commandList(const CLI::App& app) {
  std::size_t width = 0;
  const auto subs = app.get_subcommands([](const CLI::App*) { return true; });
  for (const CLI::App* sub : subs) width = std::max(width, sub->get_name().size());
  std::string out;
  for (const CLI::App* sub : subs) {
    out += "  " + sub->get_name() + std::string(width + 2 - sub->get_name().size(), ' ') + sub->get_description() + "\n";
  }
  return out;
}

}  // namespace haarcast::cli

#include "eval_methods.h"

#include <algorithm>
#include <cstdio>
#include <sstream>

#include "number_format.h"

namespace haarcast::app {
// 1,024 → "1.0 KiB": storage spans five decades here.
std::string bytesText(double bytes) {
  const char* units[] = {"B", "KiB", "MiB", "GiB"};
  int u = 0;
  while (bytes >= 1024.0 && u < 3) bytes /= 1024.0, ++u;
  return fmt(bytes, u == 0 ? 0 : 1) + " " + units[u];
}

std::vector<RankedMaterial> rankedMaterials() {
  return {{"rough", "ggx:0.3"}, {"glossy", "ggx:0.1"}, {"near-mirror", "ggx:0.02"}};
}

std::vector<int> ranksAscending(const std::vector<double>& values) {
  std::vector<int> ranks(values.size());
  for (std::size_t i = 0; i < values.size(); ++i) {
    int below = 0;
    for (const double v : values) below += v < values[i] ? 1 : 0;
    ranks[i] = below + 1;
  }
  return ranks;
}

std::string methodRankingMarkdown(const nlohmann::json& ranked) {
  const auto& c = ranked["config"];
  std::ostringstream md;
  md << "\n## Methods ranked: speed, storage, truth\n\n"
     << "On " << c["model"].get<std::string>() << " under " << c["probe"].get<std::string>() << ", "
     << c["frame"].get<int>() << "² frames, map level " << c["level"].get<int>()
     << ", one sample per pixel, black background; every method at the product's defaults on the CPU backend (k = "
     << c["light_coefficients"].get<std::size_t>() << " light coefficients for the Haar-domain methods, "
     << c["theta_samples"].get<int>()
     << " θₒ samples; `splitsum` reads no map of that level). **Speed**: the median frame time of "
     << c["frames_timed"].get<int>()
     << " frames after a warm-up, the methods one after another on one machine (compare them as ratios). "
        "**Storage**: the BRDF data kept per material (`loadtest`'s figure). **Prepare**: building the renderer "
        "with eval's cache (a material's slice table and the sphere's visibility are computed once, by the first "
        "method that needs them, and read back after). **Truth**: against the Monte Carlo "
        "reference converged to a half-image difference of "
     << fmt(c["tolerance"].get<double>(), 3) << " (at most " << c["max_samples"].get<int>()
     << " samples); its **floor** is a second seed with the same samples against the first. Ranks: 1 = fastest, "
        "smallest, closest (by relative L2); the summary averages each over the three materials.\n\n";
  if (!ranked.contains("materials")) return md.str();
  std::vector<std::string> specs;
  for (const auto& [spec, m] : ranked["materials"].items()) specs.push_back(spec);
  // Rough first: the materials by their role's order.
  auto order = [&](const std::string& spec) {
    const std::string role = ranked["materials"][spec]["role"].get<std::string>();
    return role == "rough" ? 0 : role == "glossy" ? 1 : 2;
  };
  std::sort(specs.begin(), specs.end(), [&](const std::string& a, const std::string& b) { return order(a) < order(b); });

  md << "| method | mean rank: speed | storage | truth | stored per material | frame (ms):";
  for (const auto& s : specs) md << " " << s << " |";
  md << " relative L2:";
  for (const auto& s : specs) md << " " << s << " |";
  md << "\n|---|---:|---:|---:|---:|";
  for (std::size_t i = 0; i < 2 * specs.size(); ++i) md << "---:|";
  md << "\n";
  for (const auto& name : c["methods"]) {
    const std::string n = name.get<std::string>();
    const auto& s = ranked["summary"][n];
    const auto& first = ranked["materials"][specs.front()]["methods"][n];
    md << "| " << n << " | " << fmt(s["speed"].get<double>(), 1) << " | " << fmt(s["storage"].get<double>(), 1) << " | "
       << fmt(s["truth"].get<double>(), 1) << " | " << bytesText(first["stored_bytes"].get<double>()) << " |";
    for (const auto& spec : specs) md << " " << fmt(1e3 * ranked["materials"][spec]["methods"][n]["frame_seconds"].get<double>(), 1) << " |";
    for (const auto& spec : specs)
      md << " " << fmt(100.0 * ranked["materials"][spec]["methods"][n]["relative_l2"].get<double>(), 1) << " % |";
    md << "\n";
  }
  for (const auto& spec : specs) {
    const auto& m = ranked["materials"][spec];
    md << "\n### " << spec << " (" << m["role"].get<std::string>() << ")\n\nTruth: " << m["mc"]["samples"].get<int>()
       << " samples per pixel, half-image difference " << fmt(m["mc"]["half_error"].get<double>(), 4) << ". Floor "
       << fmt(m["floor"]["psnr"].get<double>()) << " dB, relative L2 " << fmt(100.0 * m["floor"]["relative_l2"].get<double>())
       << " %, brightness " << fmt(m["floor"]["brightness"].get<double>(), 3) << ".\n\n"
       << "| truth rank | method | relative L2 | brightness | PSNR (dB) | frame (ms) | speed rank | stored | storage rank | "
          "prepare (s) |\n|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|\n";
    std::vector<std::string> names;
    for (const auto& [n, v] : m["methods"].items()) names.push_back(n);
    std::stable_sort(names.begin(), names.end(), [&](const std::string& a, const std::string& b) {
      return m["methods"][a]["rank"]["truth"].get<int>() < m["methods"][b]["rank"]["truth"].get<int>();
    });
    for (const auto& n : names) {
      const auto& e = m["methods"][n];
      md << "| " << e["rank"]["truth"].get<int>() << " | " << n << " | " << fmt(100.0 * e["relative_l2"].get<double>(), 1)
         << " % | " << fmt(e["brightness"].get<double>(), 3) << " | " << fmt(e["psnr"].get<double>()) << " | "
         << fmt(1e3 * e["frame_seconds"].get<double>(), 1) << " | " << e["rank"]["speed"].get<int>() << " | "
         << bytesText(e["stored_bytes"].get<double>()) << " | " << e["rank"]["storage"].get<int>() << " | "
         << fmt(e["precompute_seconds"].get<double>(), 2) << " |\n";
    }
  }
  return md.str();
}

}  // namespace haarcast::app

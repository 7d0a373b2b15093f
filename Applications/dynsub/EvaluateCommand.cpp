// dynsub evaluate: segmentation over structures x click protocols x seeds
// against a reference labelmap (Evaluation.h), as tables and plots.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <sstream>

#include <unistd.h>

#include <CLI/CLI.hpp>

#include "CommandLine.h"
#include "Commands.h"
#include "dynsub/AtomicOutput.h"
#include "dynsub/Error.h"
#include "dynsub/Evaluation.h"
#include "dynsub/OutputSet.h"
#include "dynsub/Report.h"

namespace dynsub::app {

namespace {

struct EvaluateCommandOptions {
  std::string plan;
  std::string out;
  std::vector<std::string> splits;
  int jobs = 2;
  std::string keepLandmarks;
};

// One group of the summary: the runs of one structure under one protocol on
// one image, within one split.
struct Group {
  std::string split, image, structure, protocol;
  int runs = 0, failures = 0, collapses = 0;
  double meanDice = 0, worstDice = 1, meanLeakPercent = 0, meanMissPercent = 0, meanSeconds = 0;
  std::string worstRun;  // the subject (for a cohort) and the click seed of the worst Dice
};

std::vector<Group> summarize(const std::vector<EvaluationRun>& runs) {
  std::map<std::tuple<std::string, std::string, std::string, std::string>, Group> groups;
  std::vector<std::tuple<std::string, std::string, std::string, std::string>> order;
  for (const EvaluationRun& r : runs) {
    const auto key = std::make_tuple(r.split, r.image, r.structure, r.protocol);
    Group fresh;
    fresh.split = r.split;
    fresh.image = r.image;
    fresh.structure = r.structure;
    fresh.protocol = r.protocol;
    auto [it, inserted] = groups.try_emplace(key, fresh);
    if (inserted) order.push_back(key);
    Group& g = it->second;
    ++g.runs;
    // A failed run counts as Dice 0: a user would have no segmentation.
    const double dice = r.error.empty() ? r.dice : 0.0;
    g.failures += !r.error.empty();
    g.collapses += r.error.empty() && r.collapsed;
    g.meanDice += dice;
    if (g.worstRun.empty() || dice < g.worstDice)
      g.worstRun = (r.subject.empty() ? "" : "subject " + r.subject.substr(1) + ", ") + "seed " + std::to_string(r.seed);
    g.worstDice = std::min(g.worstDice, dice);
    if (r.error.empty() && r.referenceVolume > 0) {
      g.meanLeakPercent += 100 * r.leak / r.referenceVolume;
      g.meanMissPercent += 100 * r.miss / r.referenceVolume;
    }
    g.meanSeconds += r.seconds;
  }
  std::vector<Group> result;
  for (const auto& key : order) {
    Group g = groups.at(key);
    const int ok = g.runs - g.failures;
    g.meanDice /= g.runs;
    g.meanSeconds /= g.runs;
    g.meanLeakPercent = ok ? g.meanLeakPercent / ok : 0;
    g.meanMissPercent = ok ? g.meanMissPercent / ok : 0;
    result.push_back(g);
  }
  return result;
}

std::string csvField(const std::string& text) {
  if (text.find_first_of(",\"\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (char c : text) quoted += c == '"' ? std::string("\"\"") : std::string(1, c == '\n' ? ' ' : c);
  return quoted + "\"";
}

// A measure that was not taken (NaN: the atlas's measures of a run without an
// atlas) is an empty field, which spreadsheets and pandas read as missing.
struct CsvNumber {
  double value;
};
std::ostream& operator<<(std::ostream& out, CsvNumber n) {
  if (std::isfinite(n.value)) out << n.value;
  return out;
}

void writeRunsCsv(const std::vector<EvaluationRun>& runs, const std::string& path) {
  std::ofstream out(path);
  out << "split,image,subject,subject_snr,thick_axis,contrast,structure,protocol,seed,format,landmarks,dice,jaccard,"
         "mean_surface_distance_mm,hd95_mm,"
         "volume_mm3,reference_volume_mm3,leak_mm3,miss_mm3,collapsed,surface_on_edges,"
         "edge_strength_as_read,edge_strength_flipped,edge_strength_mirrored,edge_alignment_as_read,"
         "edge_alignment_flipped,edge_alignment_mirrored,seconds,steps,control_vertices,outside_region,"
         "trust_volume_ratio,trust_atlas_outline_distance_mm,trust_clicks_to_atlas_mm,trust_farthest_mm,"
         "trust_march_share,trust_inside_shift_mm,trust_initial_volume_ratio,trust_flags,warnings,error\n";
  out << std::setprecision(6);
  for (const EvaluationRun& r : runs) {
    using N = CsvNumber;
    out << csvField(r.split) << ',' << csvField(r.image) << ',' << csvField(r.subject) << ',' << N{r.subjectSnr} << ','
        << r.subjectThickAxis << ',' << csvField(r.subjectContrast) << ',' << csvField(r.structure) << ','
        << csvField(r.protocol) << ',' << r.seed << ',' << r.format << ',' << r.landmarks << ',' << N{r.dice} << ','
        << N{r.jaccard} << ',' << N{r.meanSurfaceDistance} << ',' << N{r.hd95} << ',' << N{r.volume} << ','
        << N{r.referenceVolume} << ',' << N{r.leak} << ',' << N{r.miss} << ',' << (r.collapsed ? 1 : 0) << ','
        << N{r.surfaceOnEdges} << ',';
    if (r.convention) {
      const ConventionScores& c = *r.convention;
      out << N{c.asRead.strength} << ',' << N{c.flipped.strength} << ',' << N{c.mirrored.strength} << ','
          << N{c.asRead.alignment} << ',' << N{c.flipped.alignment} << ',' << N{c.mirrored.alignment} << ',';
    } else {
      out << ",,,,,,";
    }
    const TrustMeasures& t = r.trust;
    out << N{r.seconds} << ',' << r.steps << ',' << r.controlVertices << ',' << N{t.outsideRegion} << ','
        << N{t.volumeRatio} << ',' << N{t.outlineDistance} << ',' << N{t.clicksToAtlas} << ','
        << N{t.farthestFromEvidence} << ',' << N{t.marchShare} << ',' << N{t.insideShift} << ',' << N{t.initialRatio}
        << ',' << csvField(r.trustFlags) << ',' << csvField(r.warnings) << ',' << csvField(r.error) << '\n';
  }
  out.close();
  if (!out) throw writeFailure(path);
}

void writeSummaryCsv(const std::vector<Group>& groups, const std::string& path) {
  std::ofstream out(path);
  out << "split,image,structure,protocol,runs,mean_dice,worst_dice,worst_run,mean_leak_percent,mean_miss_percent,"
         "collapses,failures,mean_seconds\n";
  out << std::setprecision(4);
  for (const Group& g : groups)
    out << csvField(g.split) << ',' << csvField(g.image) << ',' << csvField(g.structure) << ','
        << csvField(g.protocol) << ',' << g.runs << ','
        << g.meanDice << ',' << g.worstDice << ',' << csvField(g.worstRun) << ',' << g.meanLeakPercent << ',' << g.meanMissPercent << ','
        << g.collapses << ',' << g.failures << ',' << g.meanSeconds << '\n';
  out.close();
  if (!out) throw writeFailure(path);
}

Report summaryReport(const std::vector<Group>& groups, const std::vector<EvaluationRun>& runs,
                     const std::string& plan, double seconds) {
  Report summary;
  summary.set("plan", plan);
  summary.set("runs", runs.size());
  summary.set("wall_seconds", seconds);
  std::vector<Report> list;
  for (const Group& g : groups) {
    Report r;
    r.set("split", g.split);
    r.set("image", g.image);
    r.set("structure", g.structure);
    r.set("protocol", g.protocol);
    r.set("runs", g.runs);
    r.set("mean_dice", g.meanDice);
    r.set("worst_dice", g.worstDice);
    r.set("worst_run", g.worstRun);
    r.set("mean_leak_percent", g.meanLeakPercent);
    r.set("mean_miss_percent", g.meanMissPercent);
    r.set("collapses", g.collapses);
    r.set("failures", g.failures);
    r.set("mean_seconds", g.meanSeconds);
    list.push_back(r);
  }
  summary.set("groups", list);
  return summary;
}

std::string xmlText(const std::string& text) {
  std::string escaped;
  for (char c : text) {
    if (c == '<') {
      escaped += "&lt;";
    } else if (c == '>') {
      escaped += "&gt;";
    } else if (c == '&') {
      escaped += "&amp;";
    } else {
      escaped += c;
    }
  }
  return escaped;
}

// A strip plot of one split's Dice: a column per structure and protocol
// (grouped by image), a dot per run, a bar at the mean, the 0.80 and 0.85
// lines; collapses and failures in red. Plain SVG, for any browser.
void writeDicePlot(const std::vector<EvaluationRun>& runs, const std::vector<Group>& groups,
                   const std::string& split, const std::string& path) {
  std::vector<const Group*> columns;
  for (const Group& g : groups)
    if (g.split == split) columns.push_back(&g);
  const double left = 60, top = 30, plotHeight = 300, column = 22, bottom = 190;
  const double width = left + 20 + column * std::max<size_t>(columns.size(), 1);
  const double height = top + plotHeight + bottom;
  auto y = [&](double dice) { return top + plotHeight * (1 - dice); };
  std::ofstream out(path);
  out << std::fixed << std::setprecision(1);
  out << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << width << "\" height=\"" << height
      << "\" font-family=\"sans-serif\" font-size=\"11\">\n"
      << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
      << "<text x=\"" << left << "\" y=\"18\" font-size=\"13\">Dice per run, split '" << xmlText(split) << "'</text>\n";
  for (double tick = 0; tick <= 1.0001; tick += 0.1)
    out << "<line x1=\"" << left << "\" x2=\"" << width - 10 << "\" y1=\"" << y(tick) << "\" y2=\"" << y(tick)
        << "\" stroke=\"#eee\"/><text x=\"" << left - 6 << "\" y=\"" << y(tick) + 4 << "\" text-anchor=\"end\">"
        << std::setprecision(1) << tick << "</text>\n";
  for (double bar : {0.80, 0.85})
    out << "<line x1=\"" << left << "\" x2=\"" << width - 10 << "\" y1=\"" << y(bar) << "\" y2=\"" << y(bar)
        << "\" stroke=\"#999\" stroke-dasharray=\"4 3\"/>\n";
  for (size_t c = 0; c < columns.size(); ++c) {
    const Group& g = *columns[c];
    const double x = left + column * (c + 0.5);
    for (const EvaluationRun& r : runs) {
      if (r.split != g.split || r.image != g.image || r.structure != g.structure || r.protocol != g.protocol)
        continue;
      const bool bad = !r.error.empty() || r.collapsed;
      out << "<circle cx=\"" << x << "\" cy=\"" << y(r.error.empty() ? r.dice : 0.0) << "\" r=\"2.5\" fill=\""
          << (bad ? "#d62728" : "#1f77b4") << "\" fill-opacity=\"0.7\"><title>" << xmlText(r.structure) << ' ' << xmlText(r.protocol)
          << " seed " << r.seed << ": " << std::setprecision(3) << r.dice << "</title></circle>\n"
          << std::setprecision(1);
    }
    out << "<line x1=\"" << x - 7 << "\" x2=\"" << x + 7 << "\" y1=\"" << y(g.meanDice) << "\" y2=\""
        << y(g.meanDice) << "\" stroke=\"black\" stroke-width=\"2\"/>\n";
    out << "<text transform=\"translate(" << x + 4 << "," << top + plotHeight + 8 << ") rotate(60)\">"
        << xmlText(g.image + " " + g.structure + " " + g.protocol) << "</text>\n";
  }
  out << "</svg>\n";
  out.close();
  if (!out) throw writeFailure(path);
}

void runEvaluate(const EvaluateCommandOptions& o) {
  const EvaluationPlan plan = readEvaluationPlan(o.plan);
  const std::filesystem::path dir(o.out);
  prepareOutputDirectory(dir);
  if (!o.keepLandmarks.empty()) prepareOutputDirectory(o.keepLandmarks);
  // Each run's landmark file goes through a scratch directory (the plan and
  // the seed reproduce it); only the tables and plots are kept.
  const std::filesystem::path scratch =
      std::filesystem::temp_directory_path() / ("dynsub-evaluate-" + std::to_string(getpid()));
  struct RemoveScratch {
    std::filesystem::path path;
    ~RemoveScratch() {
      std::error_code ignored;
      std::filesystem::remove_all(path, ignored);
    }
  } removeScratch{scratch};
  EvaluationOptions options;
  options.splits = o.splits;
  options.jobs = o.jobs;
  options.landmarkDirectory = o.keepLandmarks.empty() ? scratch.string() : o.keepLandmarks;
  const auto started = std::chrono::steady_clock::now();
  const std::vector<EvaluationRun> runs = runEvaluation(plan, options, [](const EvaluationRun& r, int n, int total) {
    std::cerr << '[' << n << '/' << total << "] " << r.split << ' ' << r.image << (r.subject.empty() ? "" : " " + r.subject) << ' ' << r.structure << ' '
              << r.protocol << " seed " << r.seed << ": ";
    if (r.error.empty()) {
      std::cerr << "Dice " << std::fixed << std::setprecision(3) << r.dice << (r.collapsed ? " (collapsed)" : "")
                << ", " << std::setprecision(2) << r.seconds << " s\n";
    } else {
      std::cerr << "failed: " << r.error << '\n';
    }
  });
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  const std::vector<Group> groups = summarize(runs);

  OutputSet outputs(dir);
  // An earlier evaluation's plot of a split this one did not run would read
  // as this run's; the set keeps the plots it writes.
  std::error_code newDirectory;  // a directory the set makes holds no earlier plot
  for (const std::filesystem::directory_entry& entry : std::filesystem::directory_iterator(dir, newDirectory)) {
    const std::string name = entry.path().filename().string();
    if (entry.is_regular_file() && name.rfind("dice_", 0) == 0 && entry.path().extension() == ".svg")
      outputs.retire(name);
  }
  writeRunsCsv(runs, outputs.add("runs.csv"));
  writeSummaryCsv(groups, outputs.add("summary.csv"));
  summaryReport(groups, runs, o.plan, seconds).write(outputs.add("summary.json"));
  std::vector<std::string> splits;
  for (const EvaluationRun& r : runs)
    if (std::find(splits.begin(), splits.end(), r.split) == splits.end()) splits.push_back(r.split);
  for (const std::string& split : splits) writeDicePlot(runs, groups, split, outputs.add("dice_" + split + ".svg"));
  outputs.commit();

  std::cout << std::fixed;
  for (const Group& g : groups)
    std::cout << std::left << std::setw(8) << g.split << std::setw(16) << g.image << std::setw(24) << g.structure
              << std::setw(12) << g.protocol << std::right << " mean Dice " << std::setprecision(3) << g.meanDice
              << ", worst " << g.worstDice << ", leak " << std::setprecision(1) << g.meanLeakPercent << " %"
              << (g.collapses ? ", " + std::to_string(g.collapses) + " collapsed" : "")
              << (g.failures ? ", " + std::to_string(g.failures) + " failed" : "") << '\n';
  std::cout << runs.size() << " runs in " << std::setprecision(1) << seconds << " s; wrote " << (dir / "runs.csv").string()
            << ", summary.csv, summary.json and dice_*.svg\n";
  // Some failures are results (a user would have had no segmentation);
  // all of them say that the plan cannot be run as written.
  if (!runs.empty() && std::all_of(runs.begin(), runs.end(), [](const EvaluationRun& r) { return !r.error.empty(); }))
    throw Error(o.plan, "every one of its " + std::to_string(runs.size()) + " runs failed, the first with: " +
                            runs.front().error + " (runs.csv gives each run's error)");
}

}  // namespace

void addEvaluateCommand(CLI::App& app) {
  auto o = std::make_shared<EvaluateCommandOptions>();
  CLI::App* command = app.add_subcommand(
      "evaluate",
      "Measure segmentation over structures x click protocols x seeds against a reference labelmap: each run "
      "makes expert-like landmarks from the reference (slices, points, coverage, click scatter, mistakes, file "
      "format), segments, and scores in physical space. PLAN is a JSON file (Data/Evaluation/README.md).\n"
      "Writes DIR/runs.csv (one row per run), DIR/summary.csv and DIR/summary.json (per split, image, structure "
      "and protocol: mean and worst Dice, leak, miss, collapses) and DIR/dice_SPLIT.svg.");
  command->add_option("PLAN", o->plan, "Evaluation plan (.json)")->required();
  command->add_option("--out", o->out, "Output directory (created if missing; its parent must exist)")->required();
  command->add_option("--split", o->splits, "Run only these splits of the plan (repeatable; default: all)");
  command->add_option("--jobs", o->jobs, "Runs at once")->default_val(2)->check(numberBetween(1, 64, true));
  command->add_option(
      "--keep-landmarks", o->keepLandmarks,
      "Keep each run's landmark file in this directory (named split_image_structure_protocol_seed; created if "
      "missing, its parent must exist)");
  command->callback([o] { runEvaluate(*o); });
}

}  // namespace dynsub::app

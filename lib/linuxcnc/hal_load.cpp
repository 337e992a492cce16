// SPDX-License-Identifier: GPL-2.0-or-later
#include "linuxcnc/hal_load.hpp"

#include <algorithm>
#include <array>
#include <regex>
#include <sstream>

namespace i20::linuxcnc {
namespace {

// Components whose pins exist only while LinuxCNC itself runs: its task-side programs and
// the GUIs (their pins come with the postgui file).
constexpr std::array kRunningLinuxcncOnly{"iocontrol", "halui",  "pyvcp",    "axisui", "gladevcp",
                                          "gmoccapy",  "touchy", "qtdragon", "qtvcp",  "gscreen"};

// hostmot2 drivers other than hm2_eth talk to PCI, SPI or parallel-port cards: no virtual
// card stands in for them.
constexpr std::array kOtherHostmot2Drivers{"hm2_pci", "hm2_7i43",  "hm2_7i90",
                                           "hm2_spi", "hm2_rpspi", "hal_parport"};

std::string component_of(const std::string& name) {
  return name.substr(0, name.find('.'));
}

std::string basename(const std::string& path) {
  const auto slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

// The components a `loadusr` starts: the program's name, or the one -Wn gives.
std::vector<std::string> loadusr_components(const Statement& s) {
  std::vector<std::string> names;
  for (std::size_t i = 0; i < s.args.size(); ++i) {
    const std::string word = unquoted(s.args[i]);
    if (word == "-Wn" && i + 1 < s.args.size()) {
      names.push_back(unquoted(s.args[++i]));
    } else if (!word.empty() && word[0] != '-') {
      names.push_back(basename(word));
      break;
    }
  }
  return names;
}

bool reads_ini(const Statement& s) {
  static const std::regex kIni(R"(\[[A-Za-z0-9_]+\][A-Za-z0-9_]+)");
  return std::any_of(s.args.begin(), s.args.end(), [](const auto& a) { return std::regex_search(a, kIni); });
}

std::string first_board_ip(const Statement& s) {
  for (const auto& a : s.args) {
    const std::string word = unquoted(a);
    if (word.rfind("board_ip=", 0) != 0) continue;
    const std::string list = word.substr(9);
    if (list.find(',') != std::string::npos)
      throw UsageError(s.at.text() + ": hm2_eth board_ip=" + list +
                       " names several boards: --load runs one virtual card (lint the files of one board)");
    return list;
  }
  return "";
}

class Planner {
 public:
  void module(const Statement& s) {
    if (s.args.empty()) return;
    const std::string module = unquoted(s.args[0]);
    if (std::find(kOtherHostmot2Drivers.begin(), kOtherHostmot2Drivers.end(), module) !=
        kOtherHostmot2Drivers.end())
      throw UsageError(s.at.text() + ": loadrt " + module +
                       ": --load runs the files against a virtual 7I96S or 7I92T, which hm2_eth drives; this "
                       "configuration's card is not one");
    if (module == "hm2_eth") {
      const std::string ip = first_board_ip(s);
      if (!ip.empty()) plan.need.board_ip = ip;
    }
    if (module == "motmod" || module == "[EMCMOT]EMCMOT") plan.need.motion = true;
  }

  void name(const std::string& word) {
    static const std::regex kBoard(R"(^hm2_(7i96s|7i92)\.0\.(?:8i20\.0\.([0-9])\.)?)");
    std::smatch m;
    if (!std::regex_search(word, m, kBoard)) return;
    plan.need.card = m[1].str() == "7i96s" ? "7i96s" : "7i92t-servo";
    if (m[2].matched) plan.need.channels = std::max(plan.need.channels, std::stoi(m[2].str()) + 1);
  }

  // Why `s` cannot load outside a running LinuxCNC, or "".
  std::string left_out_because(const Statement& s) {
    if (s.command == "loadusr") {
      for (const auto& c : loadusr_components(s)) user_components_.push_back(c);
      return "loadusr starts a program (a GUI or user-space component) that a running LinuxCNC provides";
    }
    for (const auto& a : s.args) {
      const std::string c = component_of(unquoted(a));
      if (std::find(kRunningLinuxcncOnly.begin(), kRunningLinuxcncOnly.end(), c) !=
              kRunningLinuxcncOnly.end() ||
          std::find(user_components_.begin(), user_components_.end(), c) != user_components_.end())
        return "names " + c + "'s pins, which exist only while LinuxCNC runs";
    }
    return "";
  }

  LoadPlan plan;

 private:
  std::vector<std::string> user_components_;
};

// `text` with physical lines [first, last] (1-based) commented out.
void comment_out(std::vector<std::string>& lines, int first, int last) {
  for (int l = first; l <= last && l <= static_cast<int>(lines.size()); ++l) lines[l - 1].insert(0, "#");
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::stringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

}  // namespace

LoadPlan plan_load(const std::vector<HalSource>& sources) {
  Planner p;
  bool hm2_eth = false;
  for (const auto& src : sources) {
    auto lines = lines_of(src.text);
    for (std::size_t i = 0; i < src.statements.size(); ++i) {
      const Statement& s = src.statements[i];
      if (s.command == "loadrt") {
        p.module(s);
        hm2_eth = hm2_eth || (!s.args.empty() && unquoted(s.args[0]) == "hm2_eth");
      }
      for (const auto& a : s.args) p.name(unquoted(a));
      p.plan.need.ini = p.plan.need.ini || reads_ini(s);
      const std::string why = p.left_out_because(s);
      if (why.empty()) continue;
      const int last =
          i + 1 < src.statements.size() ? src.statements[i + 1].at.line - 1 : static_cast<int>(lines.size());
      comment_out(lines, s.at.line, last);
      p.plan.left_out.push_back(s.at.text() + ": " + why);
    }
    std::string loadable;
    for (const auto& l : lines) loadable.append(l).append("\n");
    p.plan.loadable.push_back(std::move(loadable));
  }
  if (!hm2_eth)
    throw UsageError(
        "--load: the files load no hm2_eth board (loadrt hm2_eth board_ip=...): it runs them "
        "against a virtual 7I96S or 7I92T; give all files of the configuration");
  if (p.plan.need.board_ip.empty())
    throw UsageError(
        "--load: hm2_eth is loaded without board_ip=: name the card's address as LinuxCNC needs");
  if (p.plan.need.card == "7i96s" && p.plan.need.channels > 1) {
    std::string why = "--load: the files name 8I20 channel ";
    why += std::to_string(p.plan.need.channels - 1);
    throw UsageError(why + " on a 7I96S, which has one smart-serial channel for an 8I20");
  }
  return p.plan;
}

HalrunReading read_halrun_output(std::string_view output, const std::map<std::string, std::string>& copies) {
  static const std::regex kAt(R"(^(.+):([0-9]{1,9}): (.*)$)");
  HalrunReading r;
  std::stringstream in{std::string(output)};
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line.rfind("Note: Using POSIX", 0) == 0) continue;
    // LinuxCNC's realtime not starting is this machine's trouble, not a line of the file.
    if (line.find("rtapi_app") != std::string::npos) {
      if (!r.realtime_failed) {
        const std::size_t before = std::min<std::size_t>(r.other.size(), 2);
        r.realtime_why.assign(r.other.end() - static_cast<std::ptrdiff_t>(before), r.other.end());
        r.realtime_why.push_back(line);
      }
      r.realtime_failed = true;
      r.other.push_back(line);
      continue;
    }
    std::smatch m;
    const auto copy = std::regex_match(line, m, kAt) ? copies.find(m[1].str()) : copies.end();
    if (copy == copies.end()) {
      r.other.push_back(line);
      continue;
    }
    LintFinding f;
    f.at = {copy->second, std::stoi(m[2].str())};
    f.rule = "halrun";
    f.message = "halcmd: " + m[3].str();
    f.fix = "use a name the loaded components create (halcmd show pin, show param and show funct list them)";
    r.findings.push_back(std::move(f));
  }
  return r;
}

void add_halrun_findings(std::vector<LintFinding>& findings, const std::vector<LintFinding>& from_halrun) {
  const auto refused_already = [&](const SourceLine& at) {
    return std::any_of(findings.begin(), findings.end(), [&](const LintFinding& f) {
      return f.refused_by_halcmd && f.at.file == at.file && f.at.line == at.line;
    });
  };
  std::vector<LintFinding> added;
  for (const auto& f : from_halrun)
    if (!refused_already(f.at)) added.push_back(f);
  findings.insert(findings.end(), added.begin(), added.end());
}

}  // namespace i20::linuxcnc

// The options of a simulated trial, generated from its settings (trials/trial_fields.h) for
// `fvp run` and `fvp experiment`: each setting's flag, help, checks and default come from the
// one list that also makes Python's keywords and result.json's settings. Names are parsed into
// the run specification's types here; nothing after parsing compares them.
#pragma once

#include <CLI/CLI.hpp>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "cli_checks.h"
#include "commands.h"
#include "fvp/accel/backend_choice.h"
#include "fvp/host/nbv/stop_rule.h"
#include "fvp/robot/sim/sim_clock.h"
#include "fvp/trials/trial_fields.h"

namespace fvp::apps {

/// Adds one trial setting to a command: the setting's type decides the option's kind.
class TrialOptionAdder {
 public:
  TrialOptionAdder(CLI::App* cmd, bool with_per_trial) : cmd_(cmd), per_trial_(with_per_trial) {}

  template <typename T>
  void operator()(const host::nbv::RunField& field, T& member) {
    if (field.per_trial && !per_trial_) return;
    if constexpr (std::is_same_v<T, double>) {
      // Numbers: above 0, or at least 0 where 0 is a choice.
      cmd_->add_option(std::string(field.flag), member, std::string(field.help))
          ->check(numberFromZero(field.may_be_zero))
          ->capture_default_str();
    } else {
      add(std::string(field.flag), std::string(field.help), field.vocabulary, member);
    }
  }

 private:
  using Vocabulary = host::nbv::FieldVocabulary;

  void add(const std::string& flag, const std::string& help, Vocabulary vocabulary,
           std::string& name) {
    auto* option = cmd_->add_option(flag, name, help);
    if (vocabulary == Vocabulary::kPlanner)
      option->check(CLI::IsMember(plannerNames()))->capture_default_str();
    if (vocabulary == Vocabulary::kMapEngine) option->check(CLI::IsMember(mapEngineNames()));
  }
  void add(const std::string& flag, const std::string& help, Vocabulary,
           std::filesystem::path& path) {
    cmd_->add_option_function<std::string>(
            flag, [&path](const std::string& text) { path = text; }, help)
        ->check(CLI::ExistingFile);
  }
  void add(const std::string& flag, const std::string& help, Vocabulary, std::uint64_t& value) {
    cmd_->add_option(flag, value, help)->check(decimalUnsigned())->capture_default_str();
  }
  void add(const std::string& flag, const std::string& help, Vocabulary,
           std::optional<int>& value) {
    cmd_->add_option_function<int>(
            flag, [&value](int n) { value = n > 0 ? std::optional<int>(n) : std::nullopt; }, help)
        ->check(decimalUnsigned());
  }
  void add(const std::string& flag, const std::string& help, Vocabulary,
           std::optional<double>& value) {
    cmd_->add_option_function<double>(
            flag, [&value](double x) { value = x; }, help)
        ->check(numberFromZero(true));
  }
  void add(const std::string& flag, const std::string& help, Vocabulary, bool& value) {
    cmd_->add_flag(flag + ",!--no-" + flag.substr(2), value,
                   help + " (default: " + (value ? "on" : "off") + ")");
  }
  void add(const std::string& flag, const std::string& help, Vocabulary,
           std::optional<bool>& value) {
    cmd_->add_flag_function(
        flag + ",!--no-" + flag.substr(2), [&value](std::int64_t count) { value = count > 0; },
        help);
  }
  void add(const std::string& flag, const std::string& help, Vocabulary,
           accel::BackendChoice& choice) {
    addChoiceOption(
        cmd_, flag, choice, accel::kBackendChoices,
        [](accel::BackendChoice c) { return accel::toString(c); }, help);
  }
  void add(const std::string& flag, const std::string& help, Vocabulary,
           host::nbv::StopRule& rule) {
    addChoiceOption(
        cmd_, flag, rule, host::nbv::kStopRules,
        [](host::nbv::StopRule r) { return host::nbv::toString(r); }, help);
  }
  void add(const std::string& flag, const std::string& help, Vocabulary,
           robot::sim::SimClock::Mode& mode) {
    using Mode = robot::sim::SimClock::Mode;
    addChoiceOption(cmd_, flag, mode, std::vector<Mode>{Mode::kWall, Mode::kFixed},
                    robot::sim::SimClock::modeName, help);
  }

  CLI::App* cmd_;
  bool per_trial_;
};

/// The trial's settings as options of `cmd`. with_per_trial: also the planner and the seed
/// (`fvp run`; `fvp experiment` takes lists of them instead).
inline void addTrialOptions(CLI::App* cmd, trials::TrialOptions& trial, bool with_per_trial) {
  trials::visitTrialFields(trial, TrialOptionAdder(cmd, with_per_trial));
}

}  // namespace fvp::apps

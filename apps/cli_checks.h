// Option checks shared by the subcommands. CLI11 converts integers with strtoull/strtoll in
// base 0, so on its own it reads "-1" as 2^64-1 for an unsigned option and "010" as 8; it
// also lets "inf" and "nan" through its range checks. These validators run on the option's
// text before any conversion.
#pragma once

#include <CLI/CLI.hpp>

#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <vector>

#include "fvp/accel/backend_choice.h"
#include "fvp/host/core/number_text.h"
#include "fvp/trials/experiment_directory.h"

namespace fvp::apps {

/// A decimal integer in [0, 2^64 - 1]: digits only (no sign, no 0x, no leading zeros).
inline CLI::Validator decimalUnsigned() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        if (text.empty()) return "expected a non-negative decimal integer, got nothing";
        for (char c : text)
          if (c < '0' || c > '9')
            return "expected a non-negative decimal integer, got '" + text + "'";
        if (text.size() > 1 && text[0] == '0')
          return "expected a decimal integer without leading zeros, got '" + text + "'";
        errno = 0;
        (void)std::strtoull(text.c_str(), nullptr, 10);
        if (errno == ERANGE) return "'" + text + "' does not fit in 64 bits";
        return {};
      },
      "UINT", "decimalUnsigned");
}

/// A finite decimal number (no inf, nan or hexadecimal floats).
inline CLI::Validator finiteNumber() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        // Decimal text first: strtod alone takes " 5" (not "5 "), hex floats, inf and nan.
        errno = 0;
        const double v = host::isDecimalNumberText(text, false) ? std::strtod(text.c_str(), nullptr)
                                                                : std::nan("");
        if (!std::isfinite(v) || errno == ERANGE)
          return "expected a finite decimal number, got '" + text + "'";
        return {};
      },
      "NUMBER", "finiteNumber");
}

/// A finite number from zero on: above it (zero_allowed false) or at least it. (CLI::
/// PositiveNumber prints the largest double, 309 digits, as its bound.)
inline CLI::Validator numberFromZero(bool zero_allowed) {
  return CLI::Validator(
      [zero_allowed](std::string& text) -> std::string {
        std::string copy = text;
        if (std::string error = finiteNumber()(copy); !error.empty()) return error;
        const double v = std::strtod(text.c_str(), nullptr);
        if (!(zero_allowed ? v >= 0.0 : v > 0.0))
          return std::string(zero_allowed ? "expected a number of at least 0, got '"
                                          : "expected a number above 0, got '") +
                 text + "'";
        return {};
      },
      zero_allowed ? "NON_NEGATIVE" : "POSITIVE",
      zero_allowed ? "nonNegativeNumber" : "positiveNumber");
}

/// A finite number above zero.
inline CLI::Validator positiveNumber() {
  return numberFromZero(false);
}

/// A path that is not empty: `--out ""` would write nowhere (the libraries take an empty
/// directory to mean "no files") and report success.
inline CLI::Validator nonEmptyPath() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        if (text.empty()) return "expected a directory, got an empty path";
        return {};
      },
      "PATH", "nonEmptyPath");
}

/// Wraps a parser that throws std::invalid_argument (with the option's name in its message)
/// as a validator: a malformed value is a usage error (exit 2) like any other option's.
template <typename Parse>
CLI::Validator parsedBy(Parse parse, const char* name) {
  return CLI::Validator(
      [parse](std::string& text) -> std::string {
        try {
          parse(text);
        } catch (const std::invalid_argument& e) {
          // CLI11 puts the option's name in front; the parser's own "--name: " goes.
          std::string message = e.what();
          const std::size_t colon = message.find(": ");
          if (message.rfind("--", 0) == 0 && colon != std::string::npos &&
              message.find(' ') > colon)
            message.erase(0, colon + 2);
          return message;
        }
        return {};
      },
      "", name);
}

/// --shard i/n (trials::parseShard).
inline CLI::Validator shardText() {
  return parsedBy([](const std::string& t) { trials::parseShard(t); }, "shard");
}

/// --error-scale GROUP=FACTOR: a known group, a decimal factor from 0 to 1000
/// (trials::parseErrorScale). Whether the world config can take the factor is checked
/// with the config (exit 1).
inline CLI::Validator errorScaleText() {
  return parsedBy([](const std::string& t) { trials::parseErrorScale(t); }, "error scale");
}

/// An option taking one of an enum's names (nameOf(choice) for each of `choices`), parsed into
/// `target`; its default is the target's name.
template <typename Enum, typename Choices, typename NameOf>
CLI::Option* addChoiceOption(CLI::App* cmd, const std::string& flag, Enum& target,
                             const Choices& choices, NameOf nameOf, const std::string& help) {
  std::vector<std::string> names;
  for (const Enum choice : choices) names.emplace_back(nameOf(choice));
  return cmd
      ->add_option_function<std::string>(
          flag,
          [&target, choices, nameOf](const std::string& text) {
            for (const Enum choice : choices)
              if (std::string(nameOf(choice)) == text) target = choice;
          },
          help)
      ->check(CLI::IsMember(names))
      ->default_str(std::string(nameOf(target)));
}

/// --backend: a compute backend or auto, parsed into accel::BackendChoice.
inline CLI::Option* addBackendOption(CLI::App* cmd, accel::BackendChoice& choice,
                                     const std::string& help) {
  return addChoiceOption(
      cmd, "--backend", choice, accel::kBackendChoices,
      [](accel::BackendChoice c) { return accel::toString(c); }, help);
}

}  // namespace fvp::apps

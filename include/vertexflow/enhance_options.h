// The options of EnhanceOptions (enhance.h) written once: for each, its Python keyword, its CLI
// flag, its kind and range, its help, the modes it applies to, and how to read and set it. The
// CLI's flags, the Python module's keywords and signature, the stub vertexflow.pyi and the
// "does not apply" rules of validate_enhance_options are loops over this table, so an option is
// added in one place (src/enhance/enhance_options.cpp).
#pragma once

#include "vertexflow/enhance.h"

#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

namespace vertexflow {

/// A value of an option: a flag, a count, a number, a name (Choice), vertex indices, or none
/// (an OptionalInt left unset).
using OptionValue = std::variant<std::monostate, bool, long long, double, std::string, std::vector<Index>>;

enum class OptionKind {
  Bool,
  Int,
  Double,
  Choice,       ///< one of `choices`
  Indices,      ///< vertex indices (Python: a 1-D integer array; the CLI reads them from --pin FILE)
  OptionalInt,  ///< an int or none (Python None), e.g. max_rounds
};

/// Bit i set: the option applies to EnhanceMode i.
using ModeMask = unsigned;
constexpr ModeMask mode_bit(EnhanceMode mode) {
  return 1u << static_cast<unsigned>(mode);
}

struct EnhanceOptionSpec {
  std::string_view name;  ///< the Python keyword (and the C++ path's last word, mostly)
  std::string_view cpp;   ///< the member of EnhanceOptions, e.g. "flow.weights.lambda"
  /// The CLI's flag, empty when the CLI sets the option another way (--pin FILE).
  std::string_view flag;
  /// Bool options whose CLI flag sets the opposite (--no-projection sets project_to_input false).
  bool flag_negates = false;
  OptionKind kind = OptionKind::Double;
  std::vector<std::string_view> choices;  ///< Choice: the names, in the help's order
  std::vector<long long> choice_values;   ///< Choice: the enumerator each name stands for
  /// Int, Double, OptionalInt: the allowed range; *_open excludes the bound itself.
  double min = -1e308, max = 1e308;
  bool min_open = false, max_open = false;
  std::string_view help;
  ModeMask modes = 0;  ///< the modes it applies to (validate_enhance_options)
  std::function<OptionValue(const EnhanceOptions&)> get;
  std::function<void(EnhanceOptions&, const OptionValue&)> set;
};

/// Every option of EnhanceOptions that a front end sets, in the order the CLI's help and the
/// Python signature list them.
const std::vector<EnhanceOptionSpec>& enhance_option_specs();

/// The spec of the option with Python keyword `name`, or nullptr.
const EnhanceOptionSpec* find_enhance_option(std::string_view name);

/// The name of the Choice option `option`'s enumerator `value` (its integer value), as the CLI,
/// Python and the reports spell it ("input-normal", "max1999", ...); "?" for none.
std::string_view choice_name(std::string_view option, long long value);

/// The option's name as `naming` says (enhance.h, OptionNaming).
std::string option_display_name(const EnhanceOptionSpec& spec, OptionNaming naming);

/// Whether `value` lies in the spec's range (numbers), names one of its choices (Choice), or has
/// the kind's type. Throws std::invalid_argument naming the option as `naming` says otherwise.
void check_option_value(const EnhanceOptionSpec& spec, const OptionValue& value, OptionNaming naming);

/// Every option of the table by its Python name, as reports record them (vertex indices as their
/// count, none as null).
nlohmann::json enhance_options_json(const EnhanceOptions& options);

/// The value as Python writes it in a signature: True, 1.0, 'automatic', None.
std::string python_literal(const OptionValue& value);

}  // namespace vertexflow

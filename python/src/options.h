// The option table of enhance_options.h on the Python side: exported as data (the package
// vertexflow builds the signatures, docstrings and stub of enhance, enhance_file and batch from
// it), and Python keyword values turned into EnhanceOptions through it.
#pragma once

#include "convert.h"

#include "vertexflow/enhance.h"

namespace vertexflow::python {

/// Every option of the table as a dict: name, cpp, flag, flag_negates, kind ("bool", "int",
/// "float", "choice", "indices", "optional_int"), default (a Python value: None for no pins or
/// an unset optional), choices, min, max, min_open, max_open, help, modes (the names of the
/// modes it applies to, enhance_mode_name).
py::tuple enhance_option_table();

/// The names of the modes, in the order of EnhanceMode.
py::tuple enhance_mode_names();

/// EnhanceOptions with the values of `given` ({Python keyword: value}) set, the rest at their
/// defaults. Each value is checked against the table's kind and range (ValueError naming the
/// option as `naming` says); a name the table does not have raises TypeError naming `function`.
EnhanceOptions enhance_options_from(const py::dict& given, const char* function,
                                    OptionNaming naming = OptionNaming::Python);

}  // namespace vertexflow::python

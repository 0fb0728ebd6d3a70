// Reads the typed parameter lists that follow a directive: `"float fov" 45` or
// `"rgb L" [ 17 12 4 ]`. Values are checked against the declared type here, where the offending
// token's location is still known; names and value counts are checked later by ParamSet::validate.
#pragma once

#include <penumbra/params.h>

#include "parser/tokenizer.h"

namespace penumbra {

/// Reads parameters while the next token is a quoted string. Throws Error at the offending token.
ParamSet parse_param_list(Tokenizer& tok);

/// Reads one parameter; the next token must be its quoted "type name".
Param parse_param(Tokenizer& tok);

}  // namespace penumbra

// Text for messages from bytes of any origin (a file's keys, names, strings and paths): valid
// UTF-8 stays as it is; a byte that is not part of a valid UTF-8 sequence, and a control
// character other than newline and tab, becomes \xNN. So a message is always valid UTF-8 and
// cannot drive a terminal, whatever a file held.
#pragma once

#include <string>
#include <string_view>

namespace siviflow {

std::string printable_text(std::string_view bytes);

}  // namespace siviflow

// Text from files made safe to print on a terminal.
#ifndef CAMPROJ_TERMINAL_TEXT_H_
#define CAMPROJ_TERMINAL_TEXT_H_

#include <string>
#include <string_view>

namespace camproj {

// `text` with every control character a terminal could act on written as an escape: C0 controls
// other than newline and tab, DEL ("\x1b", "\x7f") and the UTF-8 encoded C1 controls U+0080 to
// U+009F ("\u009b"). Everything else, including other UTF-8, is unchanged. For ids, file names
// and messages that quote input files, before they are printed.
std::string TerminalSafe(std::string_view text);

}  // namespace camproj

#endif  // CAMPROJ_TERMINAL_TEXT_H_

#pragma once
#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>

namespace floedem {

/// The message with each control character (a newline of a quoted value, a tab) as \xNN, so
/// that it prints on one line whatever text it quotes.
std::string one_line(const std::string& message);

/// Bad input: the message names the file, the field (with its line where known) and the
/// allowed range. The command line prints it on one line and exits with code 2: the message is
/// kept to one line here, for every value it may quote (a TOML string holds newlines).
class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& message) : std::runtime_error(one_line(message)) {}
};

/// Text read from an input file (an attribute, a cell, a library's reason), fit to be quoted in
/// a one-line message: bytes outside printable ASCII as \xNN, and at most `max` characters of
/// it, "..." marking the cut. A damaged file's "units" may be any bytes, newlines included.
std::string printable(std::string_view text, std::size_t max = 60);

/// "FILE:LINE: field 'KEY': WHAT" (the line is left out when unknown, i.e. 0).
std::string input_message(const std::string& file, std::uint32_t line, const std::string& field,
                          const std::string& what);

}  // namespace floedem

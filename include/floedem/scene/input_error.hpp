#pragma once
#include <cstdint>
#include <stdexcept>
#include <string>

namespace floedem {

/// Bad input: the message names the file, the field (with its line where known) and the
/// allowed range. The command line prints it on one line and exits with code 2.
class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& message) : std::runtime_error(message) {}
};

/// "FILE:LINE: field 'KEY': WHAT" (the line is left out when unknown, i.e. 0).
std::string input_message(const std::string& file, std::uint32_t line, const std::string& field,
                          const std::string& what);

}  // namespace floedem

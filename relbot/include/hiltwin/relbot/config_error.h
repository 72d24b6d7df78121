#pragma once

#include <stdexcept>

namespace hiltwin::app {

/// A bad or missing configuration value; the message names the file, the key (and line), and
/// says what to do. The command line maps it to exit code 2.
class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace hiltwin::app

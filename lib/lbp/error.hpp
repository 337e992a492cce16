// Typed errors. Every message names what was wrong in words a user can act on.
#pragma once

#include <stdexcept>
#include <string>

namespace i20 {

// Base of every error the toolkit raises on purpose.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Bytes that break the LBP rules: impossible header, bad CRC, wrong length.
class ProtocolError : public Error {
 public:
  using Error::Error;
};

// A caller asked for something the protocol cannot express (data size 3, RPC 64, ...).
class UsageError : public Error {
 public:
  using Error::Error;
};

}  // namespace i20

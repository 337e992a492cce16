// SPDX-License-Identifier: GPL-2.0-or-later
// Setup-mode framing by pre-parsing (manual, "FRAMING"): the header byte alone (and,
// for an RPC, the stored list) says how long a command is and how long its reply is.
#pragma once

#include <string>

#include "lbp/bytes.hpp"
#include "lbp/local.hpp"

namespace i20::lbp {

struct Shape {
  std::size_t command_bytes = 0;  // header + address + data, CRC excluded
  std::size_t reply_bytes = 0;    // reply data, CRC excluded

  std::size_t wire_command_bytes() const { return command_bytes + 1; }
  std::size_t wire_reply_bytes() const { return reply_bytes + 1; }
  bool operator==(const Shape&) const = default;
};

struct ShapeResult {
  bool ok = false;
  Shape shape;
  std::string error;  // why the header cannot start a command, when !ok
};

// Shape of the command that starts with `header`. RPC shapes come from `rpc_table`.
ShapeResult shape_of(Byte header, ByteView rpc_table, std::size_t rpc_pitch = local::kRpcPitch);

// Device side: cuts an incoming byte stream into commands.
class CommandSplitter {
 public:
  struct Frame {
    Bytes command;  // without CRC
    Shape shape;
    bool crc_ok = false;
    Byte received_crc = 0;
  };
  enum class Status { Frame, NeedMore, Invalid };
  struct Next {
    Status status = Status::NeedMore;
    Frame frame;        // when status == Frame
    std::string error;  // when status == Invalid
  };

  void push(ByteView bytes) { buffer_.insert(buffer_.end(), bytes.begin(), bytes.end()); }
  // Cuts the next command off the front of the buffer. On Invalid the buffer is left as
  // it is: the device decides how to resynchronise (the 8I20 waits for a quiet line).
  Next next(ByteView rpc_table, std::size_t rpc_pitch = local::kRpcPitch);
  std::size_t pending() const { return buffer_.size(); }
  void clear() { buffer_.clear(); }

 private:
  Bytes buffer_;
};

// Host side: splits the replies to a batch by their expected lengths and checks CRCs.
class ReplySplitter {
 public:
  struct Reply {
    Bytes data;
    bool crc_ok = false;
    Byte received_crc = 0;
    Byte expected_crc = 0;
  };

  explicit ReplySplitter(std::vector<std::size_t> reply_data_sizes);
  void push(ByteView bytes);
  // The next complete reply, in order; nullopt until enough bytes have arrived.
  std::optional<Reply> next();
  // Wire bytes still missing for the whole batch.
  std::size_t bytes_missing() const;
  std::size_t replies_taken() const { return taken_; }
  // Bytes received beyond the last expected reply (a sign of lost framing).
  std::size_t surplus_bytes() const;

 private:
  std::vector<std::size_t> sizes_;
  std::size_t taken_ = 0;
  Bytes buffer_;
};

// Checks a single reply on the wire (data followed by CRC). Throws ProtocolError on a
// wrong length or a CRC mismatch; returns the data.
Bytes check_reply(ByteView wire, std::size_t data_bytes);

}  // namespace i20::lbp

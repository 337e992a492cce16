// SPDX-License-Identifier: GPL-2.0-or-later
// The simulated 8I20's EEPROM: a small byte image, optionally backed by a file so NV
// values survive a restart of the simulator. Every write goes through to the file at
// once (a real EEPROM keeps what it was given the moment the cell write completes).
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>

#include "lbp/bytes.hpp"
#include "sim/register_map.hpp"

namespace i20::sim {

class EepromStore {
 public:
  // In memory only, with the map's NV defaults (unprogrammed cells read 0xFF).
  EepromStore(const RegisterMap& map, std::size_t size);
  // Backed by `file`: loaded if it exists (it must hold exactly `size` bytes), else
  // created with the defaults. Throws ConfigError if the file cannot be read or written.
  EepromStore(const RegisterMap& map, std::size_t size, std::filesystem::path file);

  std::size_t size() const { return image_.size(); }
  lbp::Byte at(std::size_t offset) const { return image_.at(offset); }
  lbp::ByteView bytes() const { return image_; }
  // Stores `data` at `offset` (must fit) and writes the image through to the file.
  void write(std::size_t offset, lbp::ByteView data);
  const std::optional<std::filesystem::path>& file() const { return file_; }

  // The image a fresh card has: defaults of every EEPROM register, 0xFF elsewhere.
  static lbp::Bytes defaults(const RegisterMap& map, std::size_t size);

 private:
  void persist() const;

  lbp::Bytes image_;
  std::optional<std::filesystem::path> file_;
};

}  // namespace i20::sim

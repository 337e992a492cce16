// SPDX-License-Identifier: GPL-2.0-or-later
#include "sim/eeprom_store.hpp"

#include <fstream>
#include <iterator>

#include "sim/error.hpp"

namespace i20::sim {

EepromStore::EepromStore(const RegisterMap& map, std::size_t size) : image_(defaults(map, size)) {}

EepromStore::EepromStore(const RegisterMap& map, std::size_t size, std::filesystem::path file)
    : file_(std::move(file)) {
  std::error_code ec;
  if (!std::filesystem::exists(*file_, ec)) {
    image_ = defaults(map, size);
    persist();
    return;
  }
  std::ifstream in(*file_, std::ios::binary);
  if (!in) throw ConfigError("cannot read EEPROM image " + file_->string() + ": check its permissions");
  image_.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  if (image_.size() != size)
    throw ConfigError("EEPROM image " + file_->string() + " holds " + std::to_string(image_.size()) +
                      " bytes, expected " + std::to_string(size) + ": delete it to start from defaults");
}

void EepromStore::write(std::size_t offset, lbp::ByteView data) {
  if (offset + data.size() > image_.size())
    throw ConfigError("EEPROM write past the end of the " + std::to_string(image_.size()) + "-byte image");
  std::copy(data.begin(), data.end(), image_.begin() + static_cast<std::ptrdiff_t>(offset));
  persist();
}

lbp::Bytes EepromStore::defaults(const RegisterMap& map, std::size_t size) {
  lbp::Bytes image(size, 0xFF);
  for (const auto& r : map.all()) {
    if (r.space != Space::Eeprom || !r.default_value || r.address + r.bytes() > size) continue;
    const auto value = static_cast<std::uint64_t>(*r.default_value);
    for (unsigned i = 0; i < r.bytes(); ++i) image[r.address + i] = static_cast<lbp::Byte>(value >> (8 * i));
  }
  return image;
}

void EepromStore::persist() const {
  if (!file_) return;
  // Write a sibling file and rename it over the old one, so a crash of the simulator
  // never leaves a half-written image behind (torn writes are injected on purpose only).
  const auto temp = std::filesystem::path(file_->string() + ".tmp");
  {
    std::ofstream out(temp, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(image_.data()), static_cast<std::streamsize>(image_.size()));
    if (!out) throw ConfigError("cannot write EEPROM image " + temp.string() + ": check the directory");
  }
  std::error_code ec;
  std::filesystem::rename(temp, *file_, ec);
  if (ec) throw ConfigError("cannot replace EEPROM image " + file_->string() + ": " + ec.message());
}

}  // namespace i20::sim

// SPDX-License-Identifier: GPL-2.0-or-later
// The host-side reply splitter (lib/lbp preparse): expected reply sizes and the bytes
// that came back, in arbitrary pieces. Replies are cut exactly at the sizes asked for,
// whatever arrives, and the byte accounting adds up.
//
// Input: [count][count sizes 0..15][chunk length, chunk bytes]...
#include <cstddef>
#include <cstdint>

#include "fuzz_support.hpp"
#include "lbp/crc8.hpp"
#include "lbp/preparse.hpp"

namespace {

using namespace i20;

void run(fuzz::Input& in) {
  std::vector<std::size_t> sizes(in.byte() % 64);
  std::size_t wire_total = 0;
  for (auto& s : sizes) {
    s = in.byte() % 16;
    wire_total += s + 1;
  }
  lbp::ReplySplitter splitter(sizes);
  fuzz::require(splitter.bytes_missing() == wire_total, "nothing received: the whole batch is missing");
  std::size_t received = 0, taken_bytes = 0;
  while (!in.empty()) {
    const auto chunk = in.take(in.byte() % 48 + 1);
    received += chunk.size();
    splitter.push(chunk);
    while (auto reply = splitter.next()) {
      const std::size_t index = splitter.replies_taken() - 1;
      fuzz::require(reply->data.size() == sizes[index], "a reply has the size asked for");
      fuzz::require(reply->expected_crc == lbp::crc8(reply->data), "expected_crc is the CRC of the data");
      fuzz::require(reply->crc_ok == (reply->received_crc == reply->expected_crc),
                    "crc_ok compares the CRCs");
      taken_bytes += reply->data.size() + 1;
      // check_reply agrees with the splitter on the same bytes.
      lbp::Bytes wire = reply->data;
      wire.push_back(reply->received_crc);
      if (reply->crc_ok)
        fuzz::require(lbp::check_reply(wire, sizes[index]) == reply->data, "check_reply returns the data");
      else
        fuzz::expect_only_toolkit_errors([&] { (void)lbp::check_reply(wire, sizes[index]); });
    }
    const std::size_t buffered = received - taken_bytes;
    const std::size_t want = wire_total - taken_bytes;
    fuzz::require(splitter.bytes_missing() == (want > buffered ? want - buffered : 0),
                  "bytes_missing adds up");
    fuzz::require(splitter.surplus_bytes() == (buffered > want ? buffered - want : 0),
                  "surplus_bytes adds up");
  }
  fuzz::require(splitter.replies_taken() <= sizes.size(), "never more replies than asked for");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::Input in(data, size);
  fuzz::expect_only_toolkit_errors([&] { run(in); });
  // check_reply on the raw input against every length.
  for (std::size_t n = 0; n < 10; ++n)
    fuzz::expect_only_toolkit_errors([&] { (void)lbp::check_reply(lbp::ByteView(data, size), n); });
  return 0;
}

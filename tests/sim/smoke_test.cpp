#include <gtest/gtest.h>

#include "lbp/crc8.hpp"
#include "sim/virtual_8i20.hpp"

using namespace i20;

TEST(SimSmoke, Cookie) {
  sim::Virtual8i20 card;
  const lbp::Bytes cmd{0xDF, lbp::crc8(lbp::Bytes{0xDF})};
  card.receive(cmd, sim::Clock::time_point{});
  const auto out = card.take_output();
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[0], 0x5A);
}

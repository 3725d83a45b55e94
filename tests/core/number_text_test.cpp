// The numbers the folder's text files hold (faces.csv, OBJ meshes) are
// written without printf but must read exactly as printf wrote them.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "core/number_text.h"

namespace g2p {
namespace {

std::string printf_text(const char* format, double value) {
  char text[512];
  std::snprintf(text, sizeof text, format, value);
  return text;
}

TEST(NumberText, ReadsAsPrintfWroteIt) {
  std::vector<double> values = {0.0,
                                -0.0,
                                1.0,
                                -1.0,
                                0.5,
                                1e-5,
                                1e-4,
                                123456789.0,
                                1e9,
                                1e21,
                                1.5e-300,
                                5e-324,
                                0.12345,
                                0.99995,
                                1.00005,
                                2.5e-7,
                                3.14159265358979,
                                std::numeric_limits<double>::max(),
                                std::numeric_limits<double>::infinity(),
                                -std::numeric_limits<double>::infinity()};
  std::mt19937_64 random(11);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::uniform_int_distribution<int> exponent(-40, 40);
  for (int i = 0; i < 20000; ++i) {
    const double x = (unit(random) - 0.5) * std::pow(10.0, exponent(random));
    values.push_back(x);
    values.push_back(static_cast<float>(x));  // as the OBJ writer's float positions
  }
  for (double x : values) {
    SCOPED_TRACE(printf_text("%.17g", x));
    for (int digits : {4, 6, 9}) {
      std::string general;
      detail::append_general(general, x, digits);
      EXPECT_EQ(general, printf_text(("%." + std::to_string(digits) + "g").c_str(), x));
    }
    if (std::abs(x) < 1e30) {
      std::string fixed;
      detail::append_fixed(fixed, x, 4);
      EXPECT_EQ(fixed, printf_text("%.4f", x));
    }
  }
  std::string huge;
  detail::append_fixed(huge, 1e300, 4);  // beyond the buffer: a whole number, never cut short
  EXPECT_EQ(std::stod(huge), 1e300);
  std::string nan;
  detail::append_general(nan, std::nan(""), 9);
  EXPECT_EQ(nan, printf_text("%.9g", std::nan("")));
  for (long long n : {0LL, -1LL, 7LL, 2147483647LL, -2147483648LL, 9223372036854775807LL}) {
    std::string text;
    detail::append_integer(text, n);
    EXPECT_EQ(text, std::to_string(n));
  }
}

// The mesh writer's vertex coordinates: the shortest text reads back as the
// same float (strtof) and is never longer than "%.9g" of it.
TEST(NumberText, ShortestFloatReadsBackAsTheSameFloat) {
  std::mt19937_64 random(12);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_int_distribution<int> exponent(-8, 4);
  std::vector<float> values = {0.0f, -0.0f, 1.0f, -0.20738289f, 0.1f, 1e-7f, 3.4e38f, -1.17549435e-38f};
  for (int i = 0; i < 40000; ++i) values.push_back(static_cast<float>(unit(random) * std::pow(10.0, exponent(random))));
  std::size_t shorter = 0;
  for (float x : values) {
    std::string text;
    detail::append_shortest(text, x);
    const float back = std::strtof(text.c_str(), nullptr);
    EXPECT_EQ(std::memcmp(&back, &x, sizeof x), 0) << text << " for " << printf_text("%.9g", x);
    const std::string nine = printf_text("%.9g", x);
    EXPECT_LE(text.size(), nine.size()) << text << " against " << nine;
    shorter += text.size() < nine.size() ? 1 : 0;
  }
  EXPECT_GT(shorter, values.size() / 2);  // most coordinates need fewer than 9 digits
}

}  // namespace
}  // namespace g2p

// Messages are text: printable_text keeps valid UTF-8 and escapes every other byte and every
// control character but newline and tab, and Status::error applies it to every message.
#include "siviflow/printable_text.h"

#include <string>

#include <gtest/gtest.h>

#include "siviflow/status.h"

namespace siviflow {
namespace {

// Whether `s` is well-formed UTF-8 (RFC 3629), checked independently of the code under test.
bool valid_utf8(const std::string& s) {
  size_t i = 0;
  while (i < s.size()) {
    const auto b = static_cast<unsigned char>(s[i]);
    size_t n = b < 0x80 ? 1 : (b >> 5) == 0x6 ? 2 : (b >> 4) == 0xE ? 3 : (b >> 3) == 0x1E ? 4 : 0;
    if (n == 0 || i + n > s.size()) return false;
    uint32_t cp = n == 1 ? b : b & (0x7F >> n);
    for (size_t k = 1; k < n; ++k) {
      const auto c = static_cast<unsigned char>(s[i + k]);
      if ((c & 0xC0) != 0x80) return false;
      cp = (cp << 6) | (c & 0x3F);
    }
    const uint32_t min[] = {0, 0, 0x80, 0x800, 0x10000};
    if (cp < min[n] || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) return false;
    i += n;
  }
  return true;
}

TEST(PrintableText, KeepsValidUtf8AndNewlinesAndTabs) {
  const std::string text = "ASCII, é, ×, 水, 🌊\nnext line\tand a tab";
  EXPECT_EQ(printable_text(text), text);
}

TEST(PrintableText, EscapesBytesThatAreNotUtf8) {
  EXPECT_EQ(printable_text("a\xFF" "b"), "a\\xFFb");
  EXPECT_EQ(printable_text("\x80"), "\\x80");                 // a lone continuation byte
  EXPECT_EQ(printable_text("\xC0\xAF"), "\\xC0\\xAF");        // an overlong '/'
  EXPECT_EQ(printable_text("\xED\xA0\x80"), "\\xED\\xA0\\x80");  // a surrogate
  EXPECT_EQ(printable_text("\xF4\x90\x80\x80"), "\\xF4\\x90\\x80\\x80");  // above U+10FFFF
  EXPECT_EQ(printable_text("\xE2\x82"), "\\xE2\\x82");        // cut short at the end
  EXPECT_EQ(printable_text("\xE2\x82" "A"), "\\xE2\\x82A");   // cut short before a letter
}

TEST(PrintableText, EscapesControlCharacters) {
  EXPECT_EQ(printable_text("\x1B[31mred"), "\\x1B[31mred");  // no terminal colours
  EXPECT_EQ(printable_text(std::string("nul\0here", 8)), "nul\\x00here");
  EXPECT_EQ(printable_text("del\x7F"), "del\\x7F");
  EXPECT_EQ(printable_text("cr\r"), "cr\\x0D");
}

TEST(PrintableText, EveryByteStringComesOutValid) {
  // Every one- and two-byte string, and three-byte ones around the hard cases.
  for (int a = 0; a < 256; ++a) {
    for (int b = 0; b < 256; ++b) {
      const std::string bytes{static_cast<char>(a), static_cast<char>(b)};
      ASSERT_TRUE(valid_utf8(printable_text(bytes))) << a << " " << b;
      for (int c : {0x00, 0x41, 0x80, 0xBF, 0xC3, 0xE2, 0xFF}) {
        const std::string three = bytes + static_cast<char>(c);
        ASSERT_TRUE(valid_utf8(printable_text(three))) << a << " " << b << " " << c;
      }
    }
  }
}

TEST(PrintableText, StatusMessagesAreText) {
  const Status status = Status::error("scene.json: key 'riv\xFF\x1B' is unknown");
  EXPECT_EQ(status.message(), "scene.json: key 'riv\\xFF\\x1B' is unknown");
  EXPECT_TRUE(valid_utf8(status.message()));
}

}  // namespace
}  // namespace siviflow

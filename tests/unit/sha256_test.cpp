// SHA-256 against the FIPS 180-4 / NIST example vectors, and fed in pieces of every size across
// the 64-byte block and the padding's 56-byte boundary.
#include "siviflow/sha256.h"

#include <gtest/gtest.h>

#include <string>

namespace siviflow {
namespace {

TEST(Sha256, NistVectors) {
  EXPECT_EQ(sha256_hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(sha256_hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(sha256_hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  EXPECT_EQ(sha256_hex(std::string(1000000, 'a')),
            "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}

TEST(Sha256, PiecesGiveTheDigestOfTheWhole) {
  std::string message;
  for (int i = 0; i < 300; ++i) message += static_cast<char>(i * 7 + 3);
  for (size_t length : {55u, 56u, 63u, 64u, 65u, 119u, 120u, 128u, 300u}) {
    const std::string whole = message.substr(0, length);
    const std::string expected = sha256_hex(whole);
    for (size_t piece = 1; piece <= 70; ++piece) {
      Sha256 hasher;
      for (size_t at = 0; at < whole.size(); at += piece) hasher.update(whole.substr(at, piece));
      ASSERT_EQ(hex_digest(hasher.finish()), expected) << length << " bytes in " << piece;
    }
  }
  // 0-byte updates change nothing; one more byte changes everything.
  Sha256 hasher;
  hasher.update("", 0);
  hasher.update("abc");
  hasher.update(nullptr, 0);
  EXPECT_EQ(hex_digest(hasher.finish()), sha256_hex("abc"));
  EXPECT_NE(sha256_hex("abd"), sha256_hex("abc"));
}

}  // namespace
}  // namespace siviflow

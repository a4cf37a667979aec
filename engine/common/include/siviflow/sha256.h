// SHA-256 (FIPS 180-4), written here so that recording what made a frame needs no crypto library.
// Incremental: a file can be hashed piece by piece as it is read.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace siviflow {

class Sha256 {
 public:
  using Digest = std::array<uint8_t, 32>;

  // Adds `size` bytes at `data` to the message.
  void update(const void* data, size_t size);
  void update(std::string_view text) { update(text.data(), text.size()); }
  // The digest of the message so far. The hasher is spent: call update() or finish() no more.
  Digest finish();

 private:
  void compress(const uint8_t* block);

  std::array<uint32_t, 8> state_{0x6a09e667u, 0xbb67ae85u, 0x3c6ef372u, 0xa54ff53au,
                                 0x510e527fu, 0x9b05688cu, 0x1f83d9abu, 0x5be0cd19u};
  std::array<uint8_t, 64> block_{};
  size_t block_bytes_ = 0;  // bytes of the message waiting in block_
  uint64_t message_bytes_ = 0;
};

// `digest` as lowercase hex, two digits a byte.
std::string hex_digest(const Sha256::Digest& digest);

// The SHA-256 of `data` as lowercase hex.
std::string sha256_hex(std::string_view data);

}  // namespace siviflow

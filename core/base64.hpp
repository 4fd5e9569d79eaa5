#pragma once
// Base64 (RFC 4648, with padding), as VTK's XML files carry binary arrays.
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace diefill {

std::string base64_encode(const void* data, std::size_t size);
// Skips whitespace; returns false on any other character outside the alphabet.
bool base64_decode(std::string_view text, std::vector<std::uint8_t>& out);

}  // namespace diefill

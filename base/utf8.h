#pragma once
/// @file
/// Strict UTF-8 validation of text from outside (files, the bus) before it reaches a parser that
/// trusts it. TinyXML 2.6 (urdfdom's parser), for one, skips a multi-byte character by its lead byte's
/// length without looking, so a lead byte at the end of the text makes it read past the terminating
/// NUL (found by fuzz_urdf). Valid here: the shortest encodings of U+0000..U+10FFFF without the UTF-16
/// surrogates U+D800..U+DFFF (RFC 3629); NUL bytes are refused too (no text file holds one, and a C
/// parser would stop there).
/// Threading: pure function.

#include <cstddef>
#include <string_view>

namespace orbed {

/// The offset of the first byte that is not part of a valid, NUL-free UTF-8 text, or npos.
std::size_t FindInvalidUtf8(std::string_view text);

}  // namespace orbed

#pragma once
/// @file
/// Replacing a file whole: the bytes go to "<path>.tmp" beside it, then a rename puts them in
/// place, so a reader — or a process restarted after a crash — sees the old file or the new one,
/// never half of one. (No fsync: this survives a process crash, not a machine crash.) Used for
/// manifests, results.json, journals and state files.
///
/// Threading: no shared state; two callers must not replace the same path at once.

#include <string>

namespace orbed {

/// Replaces `path` with `bytes`. Returns false, with *error naming the file and why, when it cannot.
bool ReplaceFile(const std::string& path, const std::string& bytes, std::string* error);

}  // namespace orbed

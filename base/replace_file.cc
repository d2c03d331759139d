#include "base/replace_file.h"

#include <cerrno>
#include <cstdio>

#include "base/format.h"

namespace orbed {

bool ReplaceFile(const std::string& path, const std::string& bytes, std::string* error) {
  const std::string temporary = path + ".tmp";
  std::FILE* out = std::fopen(temporary.c_str(), "wb");
  if (out == nullptr) {
    *error = "cannot write " + temporary + ": " + DescribeErrno(errno);
    return false;
  }
  // Every step checked: a full disk shows at fwrite, at fflush or only at fclose.
  const bool written =
      std::fwrite(bytes.data(), 1, bytes.size(), out) == bytes.size() && std::fflush(out) == 0;
  const int write_errno = errno;
  const bool closed = std::fclose(out) == 0;
  if (!written || !closed) {
    *error = "cannot write " + temporary + ": " + DescribeErrno(written ? errno : write_errno);
    std::remove(temporary.c_str());
    return false;
  }
  if (std::rename(temporary.c_str(), path.c_str()) != 0) {
    *error = "cannot rename " + temporary + " to " + path + ": " + DescribeErrno(errno);
    std::remove(temporary.c_str());
    return false;
  }
  return true;
}

}  // namespace orbed

#pragma once
// One run at a time per output file: a run takes an exclusive lock on RESULT.h5.lock before it
// creates or reopens RESULT.h5.partial, and gives it up (removing the file) when its recorder
// goes. A second run on the same name, or a --resume of a file a run is still writing, is
// refused instead of truncating the other's file under it.
#include <string>

namespace floedem {

class OutputLock {
 public:
  /// Locks `path`.lock; OutputError (exit 3), naming the file, when another process holds it.
  explicit OutputLock(const std::string& path);
  ~OutputLock();
  OutputLock(const OutputLock&) = delete;
  OutputLock& operator=(const OutputLock&) = delete;

 private:
  std::string lock_path_;
  int fd_ = -1;
};

}  // namespace floedem

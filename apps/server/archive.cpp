#include "archive.h"

#include <zip.h>

#include <algorithm>
#include <filesystem>
#include <memory>

#include "specdeform/exceptions.h"

namespace specdeform::server {

namespace {

[[noreturn]] void fail(const std::string& what) {
  throw InputError("export: the archive could not be made (" + what + ")");
}

}  // namespace

std::string zip_archive(const std::vector<OutputFile>& files) {
  zip_error_t error;
  zip_error_init(&error);
  zip_source_t* buffer = zip_source_buffer_create(nullptr, 0, 0, &error);
  if (buffer == nullptr) fail(zip_error_strerror(&error));
  zip_source_keep(buffer);  // read back after the archive is closed
  const std::unique_ptr<zip_source_t, decltype(&zip_source_free)> keep(buffer, zip_source_free);
  zip_t* archive = zip_open_from_source(buffer, ZIP_TRUNCATE, &error);
  if (archive == nullptr) fail(zip_error_strerror(&error));
  for (const OutputFile& f : files) {
    const std::filesystem::path name(f.name);
    if (name.empty() || name.is_absolute() ||
        std::find(name.begin(), name.end(), "..") != name.end()) {
      zip_discard(archive);
      throw InputError("export: " + f.name + " is outside the export's folder");
    }
    zip_source_t* data = zip_source_buffer(archive, f.bytes.data(), f.bytes.size(), 0);
    if (data == nullptr || zip_file_add(archive, name.generic_string().c_str(), data,
                                        ZIP_FL_ENC_UTF_8 | ZIP_FL_OVERWRITE) < 0) {
      if (data != nullptr) zip_source_free(data);
      const std::string what = zip_strerror(archive);
      zip_discard(archive);
      fail(what);
    }
  }
  if (zip_close(archive) < 0) {
    const std::string what = zip_strerror(archive);
    zip_discard(archive);
    fail(what);
  }
  std::string out;
  if (zip_source_open(buffer) < 0) fail("reading it back");
  zip_source_seek(buffer, 0, SEEK_END);
  out.resize(size_t(zip_source_tell(buffer)));
  zip_source_seek(buffer, 0, SEEK_SET);
  if (zip_source_read(buffer, out.data(), out.size()) != zip_int64_t(out.size())) {
    zip_source_close(buffer);
    fail("reading it back");
  }
  zip_source_close(buffer);
  return out;
}

}  // namespace specdeform::server

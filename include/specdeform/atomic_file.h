// Atomic file output: the bytes go to a temporary file beside the target, which is then renamed
// over it, so readers never see a half-written file and a failed write leaves the old file intact.
#pragma once

#include <filesystem>
#include <span>
#include <string_view>

namespace specdeform {

// Throws InputError naming the path where a file there could not be written: its folder missing
// or not writable, or the path a folder. For front ends, before any long work.
void check_writable(const std::filesystem::path& path);

// Throws InputError (naming the path) if the file cannot be written.
void write_file_atomically(const std::filesystem::path& path, std::string_view bytes);
// The same for the concatenation of `parts`, written one after the other.
void write_file_atomically(const std::filesystem::path& path,
                           std::span<const std::string_view> parts);

}  // namespace specdeform

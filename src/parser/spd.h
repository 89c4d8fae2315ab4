// Reading pbrt's .spd spectral data files. Standard library only.
#pragma once

#include <string>
#include <vector>

namespace rlpbrt {

// Reads a .spd file: whitespace-separated numbers forming (lambda [nm], value) pairs; '#'
// starts a comment that runs to the end of the line. On success appends the numbers to
// *pairs in file order (lambda0, v0, lambda1, v1, ...) and returns true. Returns false with
// a message in *error (if non-null) when the file cannot be opened, holds text that is not
// a number ("path:line: ..."), holds an odd count of numbers, or holds no numbers.
// pbrt-v3 only warns about stray text and an odd trailing value; we treat both as errors.
bool readSpdFile(const std::string& path, std::vector<double>* pairs, std::string* error);

}  // namespace rlpbrt

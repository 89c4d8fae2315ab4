// No lost work: periodic checkpoints of a render in progress (`--checkpoint SECONDS`). After a
// pass, when at least `interval` seconds have passed since the previous checkpoint (or the
// start of the render), the image so far is written to the output path with the same writer
// as the final image (temporary file + rename, so a reader never sees a partial file), with
// its real spp in the metadata.
#pragma once

#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "render/film.h"

namespace rlpbrt {

using ImageMetadata = std::vector<std::pair<std::string, std::string>>;

class Checkpointer {
public:
    // `metadata(spp, seconds)` gives the metadata of an image of `spp` samples per pixel.
    Checkpointer(std::string path, double interval,
                 std::function<ImageMetadata(int spp, double seconds)> metadata);

    // The RenderOptions::onPass hook: writes a checkpoint when one is due. A failed write is
    // reported once (a warning on stderr) and the render goes on.
    void onPass(int spp, double seconds, const Film& film);
    // Whether a checkpoint is due at render time `seconds`, and the writing of one (onPass
    // is both; the resume snapshots of render/resume.h ask due() and then write()).
    bool due(double seconds) const { return seconds - last_ >= interval_; }
    void write(int spp, double seconds, const Film& film);
    // The render time of the last checkpoint (a resumed render's start).
    void setLast(double seconds) { last_ = seconds; }

    int written() const { return written_; }
    int lastSpp() const { return lastSpp_; }

private:
    std::string path_;
    double interval_;
    std::function<ImageMetadata(int, double)> metadata_;
    double last_ = 0.0;  // render time of the last checkpoint
    int written_ = 0, lastSpp_ = 0;
    bool warned_ = false;
};

// Both hooks in turn (either may be empty).
std::function<void(int, double, const Film&)> chainOnPass(
    std::function<void(int, double, const Film&)> first,
    std::function<void(int, double, const Film&)> second);

}  // namespace rlpbrt

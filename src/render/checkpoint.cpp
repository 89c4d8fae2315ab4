#include "render/checkpoint.h"

#include <cstdio>

#include "render/image_io.h"

namespace rlpbrt {

Checkpointer::Checkpointer(std::string path, double interval,
                           std::function<ImageMetadata(int, double)> metadata)
    : path_(std::move(path)), interval_(interval), metadata_(std::move(metadata)) {}

void Checkpointer::onPass(int spp, double seconds, const Film& film) {
    if (due(seconds)) write(spp, seconds, film);
}

void Checkpointer::write(int spp, double seconds, const Film& film) {
    last_ = seconds;
    std::string err;
    if (writeImage(path_, film.toImage(), metadata_(spp, seconds), &err)) {
        ++written_;
        lastSpp_ = spp;
    } else if (!warned_) {
        warned_ = true;
        std::fprintf(stderr, "%s: warning: checkpoint not written: %s\n", path_.c_str(),
                     err.c_str());
    }
}

std::function<void(int, double, const Film&)> chainOnPass(
    std::function<void(int, double, const Film&)> first,
    std::function<void(int, double, const Film&)> second) {
    if (!first) return second;
    if (!second) return first;
    return [first = std::move(first), second = std::move(second)](int spp, double s,
                                                                  const Film& film) {
        first(spp, s, film);
        second(spp, s, film);
    };
}

}  // namespace rlpbrt

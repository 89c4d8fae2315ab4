// The OpenImageIO part of image I/O, built as a module that image_io.cpp loads on first use:
// OpenImageIO pulls in about 260 shared libraries whose loading costs ~0.4 s at every start,
// which commands that never touch an image (--parse-only, --help, bad-input errors) should not
// pay. A plain C interface keeps the boundary simple.
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string>

#include <OpenImageIO/imageio.h>

namespace {
void setError(char* err, size_t len, const std::string& msg) {
    if (!err || len == 0) return;
    std::strncpy(err, msg.c_str(), len - 1);
    err[len - 1] = '\0';
}
}  // namespace

extern "C" {

// Reads all channels of the first subimage as float. *data is malloc'ed (free with
// rlpbrt_oiio_free). Returns 1 on success.
int rlpbrt_oiio_read(const char* path, float** data, int* w, int* h, int* nc, int* eightBit,
                     char* format, size_t formatLen, char* err, size_t errLen) {
    OIIO::ImageSpec config;
    // Keep alpha unassociated: we want the stored colour values, not colour * alpha.
    config.attribute("oiio:UnassociatedAlpha", 1);
    auto in = OIIO::ImageInput::open(path, &config);
    if (!in) {
        setError(err, errLen, "cannot read image \"" + std::string(path) + "\": " + OIIO::geterror());
        return 0;
    }
    const OIIO::ImageSpec& spec = in->spec();
    if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0 || spec.depth > 1 ||
        double(spec.width) * spec.height > double(int64_t(1) << 27) || spec.nchannels > 64) {
        setError(err, errLen, "image \"" + std::string(path) + "\" has an unsupported size or layout");
        return 0;
    }
    size_t n = size_t(spec.width) * spec.height * spec.nchannels;
    float* buf = static_cast<float*>(std::malloc(n * sizeof(float)));
    if (!buf) {
        setError(err, errLen, "out of memory reading \"" + std::string(path) + "\"");
        return 0;
    }
    if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, buf)) {
        setError(err, errLen, "cannot read pixels of \"" + std::string(path) + "\": " + in->geterror());
        std::free(buf);
        return 0;
    }
    *data = buf;
    *w = spec.width;
    *h = spec.height;
    *nc = spec.nchannels;
    *eightBit = spec.format == OIIO::TypeDesc::UINT8;
    setError(format, formatLen, in->format_name());
    in->close();
    return 1;
}

void rlpbrt_oiio_free(float* data) { std::free(data); }

// Writes a 3-channel image: bytes (isByte, tagged sRGB) or floats (zip-compressed for EXR),
// with string metadata. Returns 1 on success.
int rlpbrt_oiio_write(const char* path, int w, int h, int isByte, const void* data, int nMeta,
                      const char* const* keys, const char* const* values, char* err,
                      size_t errLen) {
    OIIO::ImageSpec spec(w, h, 3, isByte ? OIIO::TypeDesc::UINT8 : OIIO::TypeDesc::FLOAT);
    std::string file(path);
    bool exr = file.size() >= 4 && (file.compare(file.size() - 4, 4, ".exr") == 0);
    if (isByte) spec.attribute("oiio:ColorSpace", "sRGB");
    if (exr) spec.attribute("compression", "zip");
    for (int i = 0; i < nMeta; ++i) spec.attribute(keys[i], values[i]);
    auto out = OIIO::ImageOutput::create(file);
    if (!out) {
        setError(err, errLen, "cannot write \"" + file + "\": " + OIIO::geterror());
        return 0;
    }
    if (!out->open(file, spec)) {
        setError(err, errLen, "cannot open \"" + file + "\": " + out->geterror());
        return 0;
    }
    if (!out->write_image(spec.format, data)) {
        std::string msg = out->geterror();
        out->close();
        setError(err, errLen, "cannot write \"" + file + "\": " + msg);
        return 0;
    }
    if (!out->close()) {
        setError(err, errLen, "cannot close \"" + file + "\": " + out->geterror());
        return 0;
    }
    return 1;
}

}  // extern "C"

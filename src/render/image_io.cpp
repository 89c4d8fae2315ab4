#include "render/image_io.h"

#include <algorithm>
#include <cassert>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>

#include <dlfcn.h>

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfStandardAttributes.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <mutex>
#include <sys/stat.h>
#include <unistd.h>

namespace rlpbrt {

namespace {

bool fail(std::string* error, const std::string& message) {
    if (error) *error = message;
    return false;
}

std::string lowerExtension(const std::string& path) {
    std::string ext = std::filesystem::path(path).extension().string();
    for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    return ext;
}

// A temporary file next to `path` (same directory, so the final rename stays on one file
// system) that is removed on destruction unless release() was called.
class TempFile {
public:
    // Creates the file; on failure name() is empty and *error says why.
    TempFile(const std::string& path, const std::string& ext, std::string* error) {
        std::filesystem::path p(path);
        std::filesystem::path dir = p.parent_path();
        std::string tmpl = (dir / ("." + p.filename().string() + ".tmp-XXXXXX" + ext)).string();
        std::vector<char> buf(tmpl.begin(), tmpl.end());
        buf.push_back('\0');
        int fd = mkstemps(buf.data(), int(ext.size()));
        if (fd < 0) {
            if (error) {
                *error = "cannot create a temporary file next to \"" + path +
                         "\": " + std::strerror(errno);
            }
            return;
        }
        // mkstemps creates the file 0600; give the result the usual permissions.
        mode_t mask = umask(0);
        umask(mask);
        fchmod(fd, 0666 & ~mask);
        ::close(fd);
        name_ = buf.data();
    }
    ~TempFile() {
        if (!name_.empty()) std::remove(name_.c_str());
    }
    TempFile(const TempFile&) = delete;
    TempFile& operator=(const TempFile&) = delete;

    const std::string& name() const { return name_; }
    void release() { name_.clear(); }

private:
    std::string name_;
};

// Writes img (3 channels, finite) as a little-endian PFM (rows bottom to top).
bool writePfm(const std::string& file, const Image& img, std::string* error) {
    std::unique_ptr<FILE, int (*)(FILE*)> f(std::fopen(file.c_str(), "wb"), &std::fclose);
    if (!f) return fail(error, "cannot open \"" + file + "\": " + std::strerror(errno));
    if (std::fprintf(f.get(), "PF\n%d %d\n-1.0\n", img.width, img.height) < 0)
        return fail(error, "write error on \"" + file + "\"");
    std::vector<unsigned char> row(size_t(img.width) * 3 * 4);
    for (int y = img.height - 1; y >= 0; --y) {
        const float* src = &img.pixels[size_t(y) * img.width * 3];
        for (size_t i = 0; i < size_t(img.width) * 3; ++i) {
            uint32_t bits;
            std::memcpy(&bits, &src[i], 4);
            for (int b = 0; b < 4; ++b) row[4 * i + b] = (unsigned char)(bits >> (8 * b));
        }
        if (std::fwrite(row.data(), 1, row.size(), f.get()) != row.size())
            return fail(error, "write error on \"" + file + "\"");
    }
    if (std::fclose(f.release()) != 0) return fail(error, "write error on \"" + file + "\"");
    return true;
}

// The OpenImageIO module (oiio/oiio_module.cpp), loaded on first use.
struct OiioModule {
    int (*read)(const char*, float**, int*, int*, int*, int*, char*, size_t, char*, size_t) =
        nullptr;
    void (*free)(float*) = nullptr;
    int (*write)(const char*, int, int, int, const void*, int, const char* const*,
                 const char* const*, char*, size_t) = nullptr;
    std::string error;
};

std::string executableDir() {
    char buf[4096];
    ssize_t n = readlink("/proc/self/exe", buf, sizeof(buf) - 1);
    if (n <= 0) return "";
    buf[n] = '\0';
    return std::filesystem::path(buf).parent_path().string();
}

const OiioModule& oiio() {
    static OiioModule module;
    static std::once_flag once;
    std::call_once(once, [] {
        // Next to the executable (installed or build tree), then the build tree itself.
        std::vector<std::string> candidates;
        if (const char* env = std::getenv("RLPBRT_OIIO_MODULE")) candidates.push_back(env);
        candidates.push_back(executableDir() + "/librlpbrt_oiio.so");
#ifdef RLPBRT_MODULE_DIR
        candidates.push_back(std::string(RLPBRT_MODULE_DIR) + "/librlpbrt_oiio.so");
#endif
        std::string tried;
        for (const auto& path : candidates) {
            void* h = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
            if (!h) {
                tried += std::string(tried.empty() ? "" : "; ") + dlerror();
                continue;
            }
            module.read = reinterpret_cast<decltype(module.read)>(dlsym(h, "rlpbrt_oiio_read"));
            module.free = reinterpret_cast<decltype(module.free)>(dlsym(h, "rlpbrt_oiio_free"));
            module.write = reinterpret_cast<decltype(module.write)>(dlsym(h, "rlpbrt_oiio_write"));
            if (module.read && module.free && module.write) return;
            module.read = nullptr;
            tried += "; " + path + " lacks the rlpbrt_oiio symbols";
        }
        module.error = "cannot load the image I/O module librlpbrt_oiio.so (" + tried + ")";
    });
    return module;
}

// EXR goes through OpenEXR directly (cheap to load); other formats through the OIIO module.
bool writeExr(const std::string& file, const Image& img, const std::vector<float>& rgb,
              const std::vector<std::pair<std::string, std::string>>& metadata,
              std::string* error) {
    try {
        Imf::Header header(img.width, img.height);
        header.compression() = Imf::ZIP_COMPRESSION;
        for (const char* c : {"R", "G", "B"}) header.channels().insert(c, Imf::Channel(Imf::FLOAT));
        for (const auto& kv : metadata)
            header.insert(kv.first, Imf::StringAttribute(kv.second));
        Imf::OutputFile out(file.c_str(), header);
        Imf::FrameBuffer fb;
        const size_t xs = 3 * sizeof(float), ys = xs * size_t(img.width);
        char* base = reinterpret_cast<char*>(const_cast<float*>(rgb.data()));
        fb.insert("R", Imf::Slice(Imf::FLOAT, base, xs, ys));
        fb.insert("G", Imf::Slice(Imf::FLOAT, base + sizeof(float), xs, ys));
        fb.insert("B", Imf::Slice(Imf::FLOAT, base + 2 * sizeof(float), xs, ys));
        out.setFrameBuffer(fb);
        out.writePixels(img.height);
    } catch (const std::exception& e) {
        return fail(error, "cannot write \"" + file + "\": " + e.what());
    }
    return true;
}

// Reads an EXR's data window as RGB (a single Y channel is replicated).
bool readExr(const std::string& path, Image* out, std::string* error, ImageFileInfo* info) {
    try {
        Imf::InputFile in(path.c_str());
        const Imath::Box2i dw = in.header().dataWindow();
        const long w = long(dw.max.x) - dw.min.x + 1, h = long(dw.max.y) - dw.min.y + 1;
        if (w <= 0 || h <= 0 || double(w) * double(h) > double(MaxImagePixels))
            return fail(error, "image \"" + path + "\" has an unsupported size");
        const Imf::ChannelList& ch = in.header().channels();
        bool rgb = ch.findChannel("R") && ch.findChannel("G") && ch.findChannel("B");
        bool grey = !rgb && ch.findChannel("Y");
        if (!rgb && !grey)
            return fail(error, "image \"" + path + "\" has neither R, G, B nor Y channels");
        Image img;
        img.width = int(w);
        img.height = int(h);
        img.channels = 3;
        img.pixels.assign(size_t(w) * size_t(h) * 3, 0.f);
        const size_t xs = 3 * sizeof(float), ys = xs * size_t(w);
        // OpenEXR addresses the buffer with data-window coordinates.
        char* base = reinterpret_cast<char*>(img.pixels.data()) -
                     (long(dw.min.x) * long(xs) + long(dw.min.y) * long(ys));
        Imf::FrameBuffer fb;
        const char* names[3] = {"R", "G", "B"};
        for (int c = 0; c < (grey ? 1 : 3); ++c)
            fb.insert(grey ? "Y" : names[c], Imf::Slice(Imf::FLOAT, base + c * sizeof(float), xs, ys));
        in.setFrameBuffer(fb);
        in.readPixels(dw.min.y, dw.max.y);
        if (grey)
            for (size_t i = 0; i < img.pixels.size(); i += 3)
                img.pixels[i + 1] = img.pixels[i + 2] = img.pixels[i];
        if (info) {
            info->format = "openexr";
            int n = 0;
            for (auto it = ch.begin(); it != ch.end(); ++it) ++n;
            info->fileChannels = n;
            info->eightBit = false;
        }
        *out = std::move(img);
    } catch (const std::exception& e) {
        return fail(error, "cannot read image \"" + path + "\": " + e.what());
    }
    return true;
}

// Writes through OIIO: `data` holds w * h * 3 bytes (isByte) or floats.
bool writeOiio(const std::string& file, int w, int h, bool isByte, const void* data,
               const std::vector<std::pair<std::string, std::string>>& metadata,
               std::string* error) {
    const OiioModule& m = oiio();
    if (!m.write) return fail(error, m.error);
    std::vector<const char*> keys, values;
    for (const auto& kv : metadata) {
        keys.push_back(kv.first.c_str());
        values.push_back(kv.second.c_str());
    }
    char err[1024] = {0};
    if (!m.write(file.c_str(), w, h, isByte ? 1 : 0, data, int(keys.size()), keys.data(),
                 values.data(), err, sizeof(err)))
        return fail(error, err);
    return true;
}

}  // namespace

float srgbToLinear(float v) {
    if (v <= 0.04045f) return v * (1.f / 12.92f);
    return std::pow((v + 0.055f) * (1.f / 1.055f), 2.4f);
}

float linearToSrgb(float v) {
    if (v <= 0.0031308f) return 12.92f * v;
    return 1.055f * std::pow(v, 1.f / 2.4f) - 0.055f;
}

bool pbrtDefaultGamma(const std::string& path) {
    std::string ext = lowerExtension(path);
    return ext == ".png" || ext == ".tga";
}

bool readImage(const std::string& path, Image* out, std::string* error, ImageFileInfo* info) {
    if (lowerExtension(path) == ".exr") return readExr(path, out, error, info);
    const OiioModule& m = oiio();
    if (!m.read) return fail(error, m.error);
    float* raw = nullptr;
    int w = 0, h = 0, nc = 0, eightBit = 0;
    char format[64] = {0}, err[1024] = {0};
    if (!m.read(path.c_str(), &raw, &w, &h, &nc, &eightBit, format, sizeof(format), err,
                sizeof(err)))
        return fail(error, err);
    std::unique_ptr<float, void (*)(float*)> buf(raw, m.free);
    if (info) {
        info->format = format;
        info->fileChannels = nc;
        info->eightBit = eightBit != 0;
    }

    Image img;
    img.width = w;
    img.height = h;
    img.channels = 3;
    img.pixels.resize(size_t(w) * h * 3);
    for (size_t i = 0; i < size_t(w) * h; ++i) {
        const float* src = buf.get() + i * size_t(nc);
        float* dst = &img.pixels[i * 3];
        if (nc < 3) {
            dst[0] = dst[1] = dst[2] = src[0];  // grey (+ alpha)
        } else {
            dst[0] = src[0];
            dst[1] = src[1];
            dst[2] = src[2];
        }
    }
    *out = std::move(img);
    return true;
}

bool checkOutputPath(const std::string& path, std::string* error) {
    const std::string ext = lowerExtension(path);
    if (ext != ".exr" && ext != ".png" && ext != ".pfm" && ext != ".hdr")
        return fail(error, "cannot write \"" + path +
                               "\": unknown image format (use .exr, .png, .pfm or .hdr)");
    std::string dir = std::filesystem::path(path).parent_path().string();
    if (dir.empty()) dir = ".";
    struct stat st;
    if (stat(dir.c_str(), &st) != 0 || !S_ISDIR(st.st_mode))
        return fail(error, "cannot write \"" + path + "\": directory \"" + dir +
                               "\" does not exist");
    if (access(dir.c_str(), W_OK) != 0)
        return fail(error, "cannot write \"" + path + "\": directory \"" + dir +
                               "\" is not writable");
    if (stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode))
        return fail(error, "cannot write \"" + path + "\": it is a directory");
    return true;
}

bool writeImage(const std::string& path, const Image& img,
                const std::vector<std::pair<std::string, std::string>>& metadata,
                std::string* error) {
    const std::string ext = lowerExtension(path);
    if (ext != ".exr" && ext != ".png" && ext != ".pfm" && ext != ".hdr") {
        return fail(error, "cannot write \"" + path +
                               "\": unknown image format (use .exr, .png, .pfm or .hdr)");
    }
    if (img.channels != 3 || img.width <= 0 || img.height <= 0 ||
        img.pixels.size() != size_t(img.width) * img.height * 3) {
        return fail(error, "cannot write \"" + path + "\": not a non-empty RGB image");
    }

    // Non-finite values are a caller bug; never let them reach the file.
    std::vector<float> clean(img.pixels);
    for (float& v : clean) {
        assert(std::isfinite(v) && "writeImage: non-finite pixel value");
        if (!std::isfinite(v)) v = 0.f;
    }

    TempFile tmp(path, ext, error);
    if (tmp.name().empty()) return false;

    bool ok;
    if (ext == ".pfm") {
        Image copy;
        copy.width = img.width;
        copy.height = img.height;
        copy.channels = 3;
        copy.pixels = std::move(clean);
        ok = writePfm(tmp.name(), copy, error);
    } else if (ext == ".png") {
        std::vector<uint8_t> bytes(clean.size());
        for (size_t i = 0; i < clean.size(); ++i) {
            float e = linearToSrgb(std::clamp(clean[i], 0.f, 1.f));
            bytes[i] = uint8_t(std::clamp(std::floor(255.f * e + 0.5f), 0.f, 255.f));
        }
        ok = writeOiio(tmp.name(), img.width, img.height, true, bytes.data(), metadata, error);
    } else {
        ok = ext == ".exr" ? writeExr(tmp.name(), img, clean, metadata, error)
                           : writeOiio(tmp.name(), img.width, img.height, false, clean.data(),
                                       {}, error);
    }
    if (!ok) return false;

    if (std::rename(tmp.name().c_str(), path.c_str()) != 0) {
        return fail(error, "cannot rename \"" + tmp.name() + "\" to \"" + path +
                               "\": " + std::strerror(errno));
    }
    tmp.release();
    return true;
}

bool writeFileAtomically(const std::string& path, const std::string& content,
                         std::string* error) {
    TempFile tmp(path, "", error);
    if (tmp.name().empty()) return false;
    {
        std::ofstream f(tmp.name(), std::ios::binary | std::ios::trunc);
        f.write(content.data(), std::streamsize(content.size()));
        f.close();
        if (!f) return fail(error, "cannot write \"" + tmp.name() + "\"");
    }
    if (std::rename(tmp.name().c_str(), path.c_str()) != 0) {
        return fail(error, "cannot rename \"" + tmp.name() + "\" to \"" + path +
                               "\": " + std::strerror(errno));
    }
    tmp.release();
    return true;
}

}  // namespace rlpbrt

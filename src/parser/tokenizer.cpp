#include "parser/tokenizer.h"

#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

namespace rlpbrt {

bool Token::isNumberLike() const {
    if (text.empty()) return false;
    char c = text[0];
    return (c >= '0' && c <= '9') || c == '.' || c == '-' || c == '+';
}

Tokenizer::Tokenizer(std::string contents, const std::string* file, Diagnostics& diag)
    : owned_(std::move(contents)), file_(file), diag_(diag) {
    data_ = owned_.data();
    size_ = owned_.size();
    skipBom();
}

Tokenizer::Tokenizer(void* map, std::size_t size, const std::string* file, Diagnostics& diag)
    : data_(static_cast<const char*>(map)), size_(size), map_(map), mapSize_(size), file_(file),
      diag_(diag) {
    skipBom();
}

Tokenizer::~Tokenizer() {
    if (map_) munmap(map_, mapSize_);
}

// Skips a UTF-8 byte order mark; columns still count from the first real character.
void Tokenizer::skipBom() {
    if (size_ >= 3 && std::memcmp(data_, "\xEF\xBB\xBF", 3) == 0) pos_ = lineStart_ = 3;
}

std::unique_ptr<Tokenizer> Tokenizer::fromFile(const std::string& path, Diagnostics& diag,
                                               const FileLoc& includedFrom) {
    struct stat st;
    if (stat(path.c_str(), &st) != 0) {
        diag.error(includedFrom, "cannot open file \"" + path + "\"");
        return nullptr;
    }
    if (S_ISDIR(st.st_mode)) {
        diag.error(includedFrom, "\"" + path + "\" is a directory, not a scene file");
        return nullptr;
    }
    // Regular files are mapped (no copy, no zero-filled buffer); others are read.
    if (S_ISREG(st.st_mode) && st.st_size > 0) {
        int fd = ::open(path.c_str(), O_RDONLY);
        if (fd >= 0) {
            void* m = mmap(nullptr, std::size_t(st.st_size), PROT_READ, MAP_PRIVATE, fd, 0);
            ::close(fd);
            if (m != MAP_FAILED) {
                madvise(m, std::size_t(st.st_size), MADV_SEQUENTIAL);
                return std::unique_ptr<Tokenizer>(
                    new Tokenizer(m, std::size_t(st.st_size), diag.intern(path), diag));
            }
        }
    }
    // Not mapped: read it, unless it claims more than any scene file should (e.g. /proc/kcore).
    if (st.st_size > (off_t(1) << 32)) {
        diag.error(includedFrom, "cannot read file \"" + path + "\" (" +
                                     std::to_string((long long)st.st_size) + " bytes)");
        return nullptr;
    }
    FILE* f = std::fopen(path.c_str(), "rb");
    if (!f) {
        diag.error(includedFrom, "cannot open file \"" + path + "\"");
        return nullptr;
    }
    std::string data;
    data.resize(std::size_t(st.st_size));
    std::size_t got = data.empty() ? 0 : std::fread(&data[0], 1, data.size(), f);
    std::fclose(f);
    if (got != data.size()) {
        diag.error(includedFrom, "cannot read file \"" + path + "\"");
        return nullptr;
    }
    return std::unique_ptr<Tokenizer>(new Tokenizer(std::move(data), diag.intern(path), diag));
}

std::unique_ptr<Tokenizer> Tokenizer::fromString(std::string text, const std::string& name,
                                                 Diagnostics& diag) {
    return std::unique_ptr<Tokenizer>(new Tokenizer(std::move(text), diag.intern(name), diag));
}

bool Tokenizer::next(Token* tok) {
    const std::size_t n = size_;
    const char* s = data_;
    while (pos_ < n) {
        char c = s[pos_];
        if (c == '\n') {
            ++pos_;
            ++line_;
            lineStart_ = pos_;
        } else if (c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v') {
            ++pos_;
        } else if (c == '#') {
            while (pos_ < n && s[pos_] != '\n') ++pos_;
        } else if (c == '"') {
            std::size_t start = pos_++;
            bool closed = false;
            while (pos_ < n) {
                char d = s[pos_];
                if (d == '"') { ++pos_; closed = true; break; }
                if (d == '\n') break;
                if (d == '\\' && pos_ + 1 < n && s[pos_ + 1] != '\n') ++pos_;
                ++pos_;
            }
            if (!closed) {
                diag_.error(here(start), "unterminated string");
                // Treat what was read as a string so parsing can go on.
                tok->text = std::string_view(s + start, pos_ - start);
                tok->loc = here(start);
                return true;
            }
            tok->text = std::string_view(s + start, pos_ - start);
            tok->loc = here(start);
            return true;
        } else if (c == '[' || c == ']') {
            tok->text = std::string_view(s + pos_, 1);
            tok->loc = here(pos_);
            ++pos_;
            return true;
        } else if (static_cast<unsigned char>(c) < 32 || c == 127) {
            diag_.error(here(pos_), "unexpected control character (code " +
                                        std::to_string(int(static_cast<unsigned char>(c))) + ")");
            ++pos_;
        } else {
            std::size_t start = pos_;
            while (pos_ < n) {
                char d = s[pos_];
                // Control characters (blanks included) end a word; the others are reported
                // on their own by the next call.
                if (d == '"' || d == '[' || d == ']' || d == '#' || d == ' ' ||
                    static_cast<unsigned char>(d) < 32 || d == 127)
                    break;
                ++pos_;
            }
            tok->text = std::string_view(s + start, pos_ - start);
            tok->loc = here(start);
            return true;
        }
    }
    return false;
}

std::string unquote(std::string_view q) {
    if (q.size() >= 1 && q.front() == '"') q.remove_prefix(1);
    // The closing quote, unless the string is unterminated and ends in an escaped quote.
    if (!q.empty() && q.back() == '"') {
        std::size_t backslashes = 0;
        while (backslashes + 1 < q.size() && q[q.size() - 2 - backslashes] == '\\') ++backslashes;
        if (backslashes % 2 == 0) q.remove_suffix(1);
    }
    if (q.find('\\') == std::string_view::npos) return std::string(q);
    std::string out;
    out.reserve(q.size());
    for (std::size_t i = 0; i < q.size(); ++i) {
        char c = q[i];
        if (c == '\\' && i + 1 < q.size()) {
            char e = q[++i];
            switch (e) {
            case 'n': out += '\n'; break;
            case 't': out += '\t'; break;
            case 'b': out += '\b'; break;
            case 'f': out += '\f'; break;
            case 'r': out += '\r'; break;
            default: out += e; break;
            }
        } else {
            out += c;
        }
    }
    return out;
}

}  // namespace rlpbrt

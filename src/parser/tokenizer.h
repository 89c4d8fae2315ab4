// Tokenizer for pbrt-v3 scene files: quoted strings, numbers, brackets, bare words, '#'
// comments. Every token carries its FileLoc. Whole files are read into memory once.
#pragma once

#include <memory>
#include <string>
#include <string_view>

#include "parser/diagnostics.h"

namespace rlpbrt {

struct Token {
    std::string_view text;  // raw text; strings keep their quotes
    FileLoc loc;
    bool isString() const { return !text.empty() && text[0] == '"'; }
    bool is(char c) const { return text.size() == 1 && text[0] == c; }
    // Looks like a number (starts with a digit, '.', '-' or '+').
    bool isNumberLike() const;
};

class Tokenizer {
public:
    // Reads a whole file. Returns null and reports at `includedFrom` if it cannot be read.
    static std::unique_ptr<Tokenizer> fromFile(const std::string& path, Diagnostics& diag,
                                               const FileLoc& includedFrom);
    static std::unique_ptr<Tokenizer> fromString(std::string text, const std::string& name,
                                                 Diagnostics& diag);

    // The next token; false at end of input. Lexical errors (unterminated string, stray
    // control character) are reported and the offending characters skipped.
    bool next(Token* tok);
    const std::string* fileName() const { return file_; }
    const std::string& path() const { return *file_; }

private:
    Tokenizer(std::string contents, const std::string* file, Diagnostics& diag);
    Tokenizer(void* map, std::size_t size, const std::string* file, Diagnostics& diag);
    void skipBom();

public:
    ~Tokenizer();
    Tokenizer(const Tokenizer&) = delete;
    Tokenizer& operator=(const Tokenizer&) = delete;

private:
    FileLoc here(std::size_t pos) const { return FileLoc{file_, line_, int(pos - lineStart_) + 1}; }

    std::string owned_;           // text held in memory (fromString, or a file that was read)
    const char* data_ = nullptr;  // the text: owned_ or a read-only mapping of the file
    std::size_t size_ = 0;
    void* map_ = nullptr;         // file mapping, unmapped by the destructor
    std::size_t mapSize_ = 0;
    const std::string* file_;
    Diagnostics& diag_;
    std::size_t pos_ = 0, lineStart_ = 0;
    int line_ = 1;
};

// Removes the quotes and resolves escapes (\" \\ \n \t \b \f \r) of a string token.
std::string unquote(std::string_view quoted);

}  // namespace rlpbrt

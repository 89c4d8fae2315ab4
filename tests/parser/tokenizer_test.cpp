// Tests of the pbrt-v3 tokenizer: token kinds and boundaries, exact line:col of every token
// (tabs count as one column, CRLF line ends), comments, string escapes and lexical errors.
#include "parser/tokenizer.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>
#include <vector>

namespace rlpbrt {
namespace {

namespace fs = std::filesystem;

// Every token of `text` as "text@line:col"; diagnostics go to `diag` (silenced).
std::vector<std::string> lex(const std::string& text, Diagnostics* diag) {
    diag->setStream(nullptr);
    auto t = Tokenizer::fromString(text, "t.pbrt", *diag);
    std::vector<std::string> out;
    Token tok;
    while (t->next(&tok)) {
        EXPECT_EQ(tok.loc.file, t->fileName());
        out.push_back(std::string(tok.text) + "@" + std::to_string(tok.loc.line) + ":" +
                      std::to_string(tok.loc.col));
    }
    return out;
}

std::vector<std::string> lex(const std::string& text) {
    Diagnostics diag;
    auto out = lex(text, &diag);
    EXPECT_EQ(diag.errorCount(), 0) << text;
    return out;
}

using Strings = std::vector<std::string>;

TEST(Tokenizer, EmptyAndBlankInput) {
    EXPECT_TRUE(lex("").empty());
    EXPECT_TRUE(lex(" \t\r\n\n\f\v  ").empty());
    EXPECT_TRUE(lex("# only a comment").empty());
    EXPECT_TRUE(lex("# comment\n  # another\n").empty());
}

TEST(Tokenizer, TokenKindsAndColumns) {
    EXPECT_EQ(lex("Shape \"sphere\" \"float radius\" [ 3 ]"),
              (Strings{"Shape@1:1", "\"sphere\"@1:7", "\"float radius\"@1:16", "[@1:31", "3@1:33",
                       "]@1:35"}));
}

TEST(Tokenizer, BracketsNeedNoSpaces) {
    EXPECT_EQ(lex("\"rgb Kd\"[.5 -1e-3 +2]"),
              (Strings{"\"rgb Kd\"@1:1", "[@1:9", ".5@1:10", "-1e-3@1:13", "+2@1:19", "]@1:21"}));
    EXPECT_EQ(lex("[[]]"), (Strings{"[@1:1", "[@1:2", "]@1:3", "]@1:4"}));
    // A quote ends a bare word and a bare word ends at a quote.
    EXPECT_EQ(lex("Shape\"sphere\"x"), (Strings{"Shape@1:1", "\"sphere\"@1:6", "x@1:14"}));
}

TEST(Tokenizer, LinesAndTabColumns) {
    // A tab counts as one column.
    EXPECT_EQ(lex("WorldBegin\n\tShape\t\"disk\"\n\n   AttributeEnd"),
              (Strings{"WorldBegin@1:1", "Shape@2:2", "\"disk\"@2:8", "AttributeEnd@4:4"}));
}

TEST(Tokenizer, CrLfLineEnds) {
    EXPECT_EQ(lex("WorldBegin\r\n  Shape \"disk\"\r\n# c\r\n\"float radius\" 2\r\n"),
              (Strings{"WorldBegin@1:1", "Shape@2:3", "\"disk\"@2:9", "\"float radius\"@4:1",
                       "2@4:16"}));
    // Old Mac CR-only files: CR is blank, so everything is on line 1.
    EXPECT_EQ(lex("A\rB"), (Strings{"A@1:1", "B@1:3"}));
}

TEST(Tokenizer, CommentsEverywhere) {
    EXPECT_EQ(lex("Shape# c1\n\"sphere\"#c2 \"not a token\"\n[1#c3\n2]#c4"),
              (Strings{"Shape@1:1", "\"sphere\"@2:1", "[@3:1", "1@3:2", "2@4:1", "]@4:2"}));
    // '#' inside a quoted string is not a comment.
    EXPECT_EQ(lex("\"a#b\" c"), (Strings{"\"a#b\"@1:1", "c@1:7"}));
    // A comment at the very end without a newline.
    EXPECT_EQ(lex("x #"), (Strings{"x@1:1"}));
}

TEST(Tokenizer, StringsKeepQuotesAndEscapes) {
    EXPECT_EQ(lex(R"("a \"b\" c" "\\" "")"),
              (Strings{R"("a \"b\" c"@1:1)", R"("\\"@1:13)", R"(""@1:18)"}));
    // Spaces and tabs inside strings are kept.
    EXPECT_EQ(lex("\"Paint - White\tMatt\""), (Strings{"\"Paint - White\tMatt\"@1:1"}));
}

TEST(Tokenizer, Unquote) {
    EXPECT_EQ(unquote("\"plain\""), "plain");
    EXPECT_EQ(unquote("\"\""), "");
    EXPECT_EQ(unquote(R"("a\"b")"), "a\"b");
    EXPECT_EQ(unquote(R"("back\\slash")"), "back\\slash");
    EXPECT_EQ(unquote(R"("\n\t\b\f\r")"), "\n\t\b\f\r");
    // Unknown escapes give the character itself.
    EXPECT_EQ(unquote(R"("\q\'")"), "q'");
}

TEST(Tokenizer, IsNumberLike) {
    Diagnostics diag;
    diag.setStream(nullptr);
    auto t = Tokenizer::fromString("1 .5 -2 +3 x \"4\" [ true e5", "t", diag);
    std::vector<bool> expect = {true, true, true, true, false, false, false, false, false};
    Token tok;
    for (bool e : expect) {
        ASSERT_TRUE(t->next(&tok));
        EXPECT_EQ(tok.isNumberLike(), e) << tok.text;
    }
    EXPECT_FALSE(t->next(&tok));
    EXPECT_FALSE(t->next(&tok));  // stays at the end
}

TEST(Tokenizer, TokenPredicates) {
    Diagnostics diag;
    auto t = Tokenizer::fromString("\"s\" [ ] w", "t", diag);
    Token tok;
    ASSERT_TRUE(t->next(&tok));
    EXPECT_TRUE(tok.isString());
    ASSERT_TRUE(t->next(&tok));
    EXPECT_TRUE(tok.is('['));
    EXPECT_FALSE(tok.is(']'));
    ASSERT_TRUE(t->next(&tok));
    EXPECT_TRUE(tok.is(']'));
    ASSERT_TRUE(t->next(&tok));
    EXPECT_FALSE(tok.isString());
    EXPECT_FALSE(tok.is('w') && tok.text.size() != 1);
}

TEST(Tokenizer, UnterminatedStringIsReportedAndRecovered) {
    Diagnostics diag;
    auto toks = lex("A \"abc\nB", &diag);
    ASSERT_EQ(diag.errorCount(), 1);
    EXPECT_EQ(diag.all()[0].str(), "t.pbrt:1:3: error: unterminated string");
    EXPECT_EQ(toks, (Strings{"A@1:1", "\"abc@1:3", "B@2:1"}));

    Diagnostics diag2;
    toks = lex("\"abc", &diag2);
    ASSERT_EQ(diag2.errorCount(), 1);
    EXPECT_EQ(diag2.all()[0].loc.col, 1);
    EXPECT_EQ(toks, (Strings{"\"abc@1:1"}));

    // An escaped quote does not close the string.
    Diagnostics diag3;
    toks = lex("\"ab\\\"", &diag3);
    EXPECT_EQ(diag3.errorCount(), 1);
    ASSERT_EQ(toks.size(), 1u);
    EXPECT_EQ(unquote("\"ab\\\""), "ab\"");
}

TEST(Tokenizer, ControlCharactersAreErrors) {
    Diagnostics diag;
    auto toks = lex(std::string("A \x01 B\n\x7f") + std::string(1, '\0') + "C", &diag);
    ASSERT_EQ(diag.errorCount(), 3);
    EXPECT_EQ(diag.all()[0].str(), "t.pbrt:1:3: error: unexpected control character (code 1)");
    EXPECT_EQ(diag.all()[1].str(), "t.pbrt:2:1: error: unexpected control character (code 127)");
    EXPECT_EQ(diag.all()[2].str(), "t.pbrt:2:2: error: unexpected control character (code 0)");
    EXPECT_EQ(toks, (Strings{"A@1:1", "B@1:5", "C@2:3"}));
    // A control character ends a bare word and is reported on its own.
    Diagnostics diag2;
    toks = lex("Shape\x02x", &diag2);
    ASSERT_EQ(diag2.errorCount(), 1);
    EXPECT_EQ(diag2.all()[0].loc.col, 6);
    EXPECT_EQ(toks, (Strings{"Shape@1:1", "x@1:7"}));
    // Inside strings, tabs are fine.
    EXPECT_EQ(lex("\"a\tb\""), (Strings{"\"a\tb\"@1:1"}));
}

TEST(Tokenizer, Utf8ByteOrderMarkIsSkipped) {
    EXPECT_EQ(lex("\xEF\xBB\xBFWorldBegin"), (Strings{"WorldBegin@1:1"}));
    // Non-ASCII bytes elsewhere are ordinary word and string characters.
    EXPECT_EQ(lex("\"caf\xC3\xA9\" x\xC3\xA9"), (Strings{"\"caf\xC3\xA9\"@1:1", "x\xC3\xA9@1:9"}));
}

TEST(Tokenizer, HugeTokens) {
    std::string big(1 << 20, 'a');
    auto toks = lex("\"" + big + "\" " + big);
    ASSERT_EQ(toks.size(), 2u);
    EXPECT_EQ(toks[0].size(), big.size() + 2 + 4);  // quotes + "@1:1"
    EXPECT_EQ(toks[1].substr(big.size()), "@1:" + std::to_string(big.size() + 4));
}

TEST(Tokenizer, FromFile) {
    fs::path dir = fs::temp_directory_path() / ("rlpbrt_tok_" + std::to_string(getpid()));
    fs::create_directories(dir);
    std::string path = (dir / "a.pbrt").string();
    std::ofstream(path) << "Shape \"sphere\"\n";
    Diagnostics diag;
    diag.setStream(nullptr);
    FileLoc from;
    auto t = Tokenizer::fromFile(path, diag, from);
    ASSERT_TRUE(t);
    EXPECT_EQ(t->path(), path);
    Token tok;
    ASSERT_TRUE(t->next(&tok));
    EXPECT_EQ(*tok.loc.file, path);
    EXPECT_EQ(tok.loc.directory(), dir.string() + "/");

    // Missing files and directories are reported at the including location.
    const std::string* inc = diag.intern("main.pbrt");
    EXPECT_FALSE(Tokenizer::fromFile((dir / "missing.pbrt").string(), diag, {inc, 3, 9}));
    ASSERT_EQ(diag.errorCount(), 1);
    EXPECT_EQ(diag.all()[0].str(),
              "main.pbrt:3:9: error: cannot open file \"" + (dir / "missing.pbrt").string() + "\"");
    EXPECT_FALSE(Tokenizer::fromFile(dir.string(), diag, {inc, 4, 1}));
    ASSERT_EQ(diag.errorCount(), 2);
    EXPECT_NE(diag.all()[1].message.find("is a directory"), std::string::npos);

    // An empty file has no tokens.
    std::ofstream((dir / "empty.pbrt").string());
    auto e = Tokenizer::fromFile((dir / "empty.pbrt").string(), diag, from);
    ASSERT_TRUE(e);
    EXPECT_FALSE(e->next(&tok));
    fs::remove_all(dir);
}

}  // namespace
}  // namespace rlpbrt

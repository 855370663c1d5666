#include "qvr/core/shell_quote.h"

#include <cstdio>
#include <string>

#include <gtest/gtest.h>

namespace qvr {

TEST(ShellQuote, QuotesPlainAndAwkwardWords) {
    EXPECT_EQ(shellQuote("plain"), "'plain'");
    EXPECT_EQ(shellQuote(""), "''");
    EXPECT_EQ(shellQuote("it's"), "'it'\\''s'");
    EXPECT_EQ(shellQuote("a b;$(rm -rf /)"), "'a b;$(rm -rf /)'");
}

TEST(ShellQuote, TheShellReadsBackTheSameWord) {
    for (const std::string word : {"it's a $HOME `x` \"y\" \\z", "''", "new\nline"}) {
        const std::string cmd = "printf %s " + shellQuote(word);
        std::FILE* p = ::popen(cmd.c_str(), "r");
        ASSERT_NE(p, nullptr);
        std::string got;
        for (int c; (c = std::fgetc(p)) != EOF;)
            got += static_cast<char>(c);
        EXPECT_EQ(::pclose(p), 0);
        EXPECT_EQ(got, word);
    }
}

}  // namespace qvr

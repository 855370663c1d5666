// The shared report writer: escaping, tables, figures through gnuplot, the page.
#include "qvr/report/html_report.h"

#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>
#include <unistd.h>

namespace qvr::report {
namespace {

namespace fs = std::filesystem;

fs::path freshDir(const std::string& name) {
    const fs::path dir =
        fs::temp_directory_path() / ("qvr-report-" + name + "-" + std::to_string(getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

std::string readAll(const fs::path& p) {
    std::ifstream in(p);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

TEST(HtmlEscape, EscapesMarkupAndQuotes) {
    EXPECT_EQ(htmlEscape("a<b>&'\"c"), "a&lt;b&gt;&amp;&#39;&quot;c");
    EXPECT_EQ(htmlEscape("plain 1.5°"), "plain 1.5°");
}

TEST(Table, FromCsvTakesTheFirstLineAsHeader) {
    const Table t = Table::fromCsv("design,fps\nqvr,90.0\nlocal,<30\n");
    ASSERT_EQ(t.rows(), 2u);
    const std::string html = t.html();
    EXPECT_NE(html.find("<th>design</th><th>fps</th>"), std::string::npos);
    EXPECT_NE(html.find("<td class='l'>qvr</td><td>90.0</td>"), std::string::npos);
    EXPECT_NE(html.find("<td>&lt;30</td>"), std::string::npos);  // escaped
    EXPECT_EQ(html.find("<td>design"), std::string::npos);       // header not repeated
}

TEST(Table, KeepsEmptyCellsAndClasses) {
    Table t({"a", "b", "c"});
    t.labelsLeft(false).row({"1", "", Cell("3", "bad")});
    EXPECT_NE(t.html().find("<td>1</td><td></td><td class='bad'>3</td>"), std::string::npos);
    Table u = Table::fromCsv("x,y\n,2\n");
    EXPECT_NE(u.html().find("<td class='l'></td><td>2</td>"), std::string::npos);
}

TEST(Plotter, DrawsATitledFigureAndFailsOnABadScript) {
    const fs::path dir = freshDir("plot");
    Plotter p(dir, 400, 300);
    if (!p.available())
        GTEST_SKIP() << "gnuplot not installed (scripts/deps.sh installs it)";
    std::ofstream(dir / "d.csv") << "1,2\n2,4\n3,9\n";
    ASSERT_TRUE(
        p.plot("ok", "squares (ms)", "set datafile separator ','\nplot 'd.csv' using 1:2\n"));
    EXPECT_GT(fs::file_size(dir / "ok.png"), 100u);
    EXPECT_NE(readAll(dir / "ok.gp").find("set title 'squares (ms)'"), std::string::npos);
    EXPECT_FALSE(p.plot("bad", "t", "plot 'no-such-file.csv' using 1:2\n"));
    EXPECT_FALSE(fs::exists(dir / "bad.png"));
    EXPECT_EQ(p.tried(), 2);
    EXPECT_EQ(p.drawn(), 1);
    EXPECT_NE(p.note().find("1/2 figures"), std::string::npos);

    HtmlReport r("t");
    r.figure(dir, "ok", "squares (ms)", 400).figure(dir, "bad", "missing", 400);
    const std::string html = r.str();
    EXPECT_NE(html.find("<img src='ok.png'"), std::string::npos);
    EXPECT_EQ(html.find("<img src='bad.png'"), std::string::npos);
    EXPECT_NE(html.find("figure not drawn"), std::string::npos);
    fs::remove_all(dir);
}

TEST(HtmlReport, WritesAPageWithVideoAndEscapedText) {
    const fs::path dir = freshDir("page");
    HtmlReport r("run <1>");
    r.heading(2, "a & b").paragraph("x<y").video("v.mp4", "still.png", 800);
    ASSERT_TRUE(r.write(dir / "report.html"));
    const std::string html = readAll(dir / "report.html");
    EXPECT_NE(html.find("<title>run &lt;1&gt;</title>"), std::string::npos);
    EXPECT_NE(html.find("<h2>a &amp; b</h2>"), std::string::npos);
    EXPECT_NE(html.find("<p>x&lt;y</p>"), std::string::npos);
    EXPECT_NE(html.find("<video controls"), std::string::npos);
    EXPECT_NE(html.find("poster='still.png'"), std::string::npos);
    EXPECT_NE(html.find("<source src='v.mp4' type='video/mp4'>"), std::string::npos);
    EXPECT_NE(html.find("</body></html>"), std::string::npos);
    fs::remove_all(dir);
}

TEST(HtmlReport, WriteFailsWithAMessageOnAnUnwritablePath) {
    const Status st = HtmlReport("t").write("/nonexistent-dir/report.html");
    ASSERT_FALSE(st);
    EXPECT_NE(st.error().find("/nonexistent-dir/report.html"), std::string::npos);
}

}  // namespace
}  // namespace qvr::report

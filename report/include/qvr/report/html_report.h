// One small report writer for every part that produces results (`qvr run`'s runtime report,
// `qvr eval`'s simulator report): HTML tables, figures drawn by gnuplot, images and videos in
// one self-contained page next to the files it links. Depends only on core, so the parts that
// produce results can use it without depending on each other.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "qvr/core/expected.h"

namespace qvr::report {

// Text for HTML element content and attribute values (both quote styles).
std::string htmlEscape(std::string_view text);

// One table cell: text (escaped when written), an optional CSS class, left-aligned or not
// (numbers are right-aligned by the page's style).
struct Cell {
    Cell(std::string cell_text) : text(std::move(cell_text)) {}  // NOLINT: implicit by design
    Cell(const char* cell_text) : text(cell_text) {}             // NOLINT: implicit by design
    Cell(std::string cell_text, std::string cell_class, bool align_left = false)
        : text(std::move(cell_text)), css_class(std::move(cell_class)), left(align_left) {}
    std::string text;
    std::string css_class;
    bool left = false;
};

class Table {
public:
    explicit Table(std::vector<std::string> header) : m_header(std::move(header)) {}
    // A CSV text's first line as the header and each further line as a row (plain
    // comma-separated cells, no quoting: what qvr's own CSV writers produce).
    static Table fromCsv(std::string_view csv);
    Table& row(std::vector<Cell> cells);
    // The first column holds names, left-aligned.
    Table& labelsLeft(bool on = true) {
        m_labels_left = on;
        return *this;
    }
    size_t rows() const { return m_rows.size(); }
    std::vector<Cell>& rowAt(size_t i) { return m_rows.at(i); }
    std::string html() const;

private:
    std::vector<std::string> m_header;
    std::vector<std::vector<Cell>> m_rows;
    bool m_labels_left = true;
};

// Draws figures with gnuplot in one folder: `name.gp` beside `name.png`, data files named
// relative to the folder. Tries the cairo PNG terminal, then libgd's. Without gnuplot nothing
// is drawn and the reports say so.
class Plotter {
public:
    Plotter(std::filesystem::path dir, int width_px, int height_px);
    bool available() const { return m_available; }
    // Writes `name.gp` (the title is set as the plot's title; it should name the units) and
    // runs it; true when `name.png` was drawn.
    bool plot(const std::string& name, const std::string& title, const std::string& body);
    int tried() const { return m_tried; }
    int drawn() const { return m_drawn; }
    const std::string& terminal() const { return m_terminal; }
    // "3/4 figures drawn by gnuplot (pngcairo terminal)" or "gnuplot not found: ...".
    std::string note() const;

private:
    std::filesystem::path m_dir;
    int m_width_px;
    int m_height_px;
    bool m_available;
    int m_tried = 0;
    int m_drawn = 0;
    std::string m_terminal;
};

// An HTML page built in order. Text arguments are escaped; `html()` takes trusted markup.
class HtmlReport {
public:
    // `extra_css` is appended to the shared style.
    explicit HtmlReport(std::string_view title, std::string_view extra_css = "");
    HtmlReport& heading(int level, std::string_view text);
    HtmlReport& paragraph(std::string_view text);
    HtmlReport& html(std::string_view markup);
    HtmlReport& table(const Table& t);
    // `<img>` of a file beside the report.
    HtmlReport& image(std::string_view src, std::string_view alt, int width_px);
    // A figure the plotter drew (heading = its title); when it was not drawn, a line saying so.
    HtmlReport& figure(const std::filesystem::path& dir, const std::string& name,
                       const std::string& title, int width_px);
    // `<video controls>` of an MP4 beside the report, with a still as its poster.
    HtmlReport& video(std::string_view src, std::string_view poster, int width_px);
    std::string str() const;
    Status write(const std::filesystem::path& path) const;

private:
    std::string m_html;
};

}  // namespace qvr::report

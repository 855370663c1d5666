// The shared report writer: HTML tables, gnuplot figures, images and video (html_report.h).
#include "qvr/report/html_report.h"

#include <cstdlib>
#include <fstream>

#include <fmt/format.h>

#include "qvr/core/shell_quote.h"

namespace qvr::report {

namespace fs = std::filesystem;

namespace {

// gnuplot string literal in single quotes: a quote is doubled.
std::string gnuplotQuote(const std::string& s) {
    std::string out = "'";
    for (char c : s)
        out += c == '\'' ? std::string("''") : std::string(1, c);
    return out + "'";
}

Status writeText(const fs::path& path, const std::string& text) {
    std::ofstream out(path, std::ios::binary);
    if (!out)
        return makeError(fmt::format("cannot write '{}'", path.string()));
    out << text;
    out.flush();
    if (!out)
        return makeError(fmt::format("error writing '{}'", path.string()));
    return Status::success();
}

}  // namespace

std::string htmlEscape(std::string_view text) {
    std::string out;
    out.reserve(text.size());
    for (char c : text) {
        switch (c) {
            case '<':
                out += "&lt;";
                break;
            case '>':
                out += "&gt;";
                break;
            case '&':
                out += "&amp;";
                break;
            case '\'':
                out += "&#39;";
                break;
            case '"':
                out += "&quot;";
                break;
            default:
                out += c;
        }
    }
    return out;
}

Table Table::fromCsv(std::string_view csv) {
    auto split = [](std::string_view line) {
        std::vector<std::string> cells;
        size_t p = 0;
        while (true) {
            const size_t c = line.find(',', p);
            cells.emplace_back(line.substr(p, c == std::string_view::npos ? line.npos : c - p));
            if (c == std::string_view::npos)
                return cells;
            p = c + 1;
        }
    };
    std::vector<std::vector<std::string>> lines;
    size_t pos = 0;
    while (pos < csv.size()) {
        size_t end = csv.find('\n', pos);
        if (end == std::string_view::npos)
            end = csv.size();
        if (end > pos)
            lines.push_back(split(csv.substr(pos, end - pos)));
        pos = end + 1;
    }
    Table t(lines.empty() ? std::vector<std::string>{} : lines.front());
    for (size_t i = 1; i < lines.size(); ++i)
        t.row(std::vector<Cell>(lines[i].begin(), lines[i].end()));
    return t;
}

Table& Table::row(std::vector<Cell> cells) {
    m_rows.push_back(std::move(cells));
    return *this;
}

std::string Table::html() const {
    std::string out = "<table>\n<tr>";
    for (const std::string& h : m_header)
        out += "<th>" + htmlEscape(h) + "</th>";
    out += "</tr>\n";
    for (const std::vector<Cell>& r : m_rows) {
        out += "<tr>";
        for (size_t i = 0; i < r.size(); ++i) {
            const Cell& c = r[i];
            std::string cls = c.css_class;
            if (c.left || (m_labels_left && i == 0))
                cls += cls.empty() ? "l" : " l";
            out += cls.empty() ? "<td>" : "<td class='" + htmlEscape(cls) + "'>";
            out += htmlEscape(c.text) + "</td>";
        }
        out += "</tr>\n";
    }
    return out + "</table>\n";
}

Plotter::Plotter(fs::path dir, int width_px, int height_px)
    : m_dir(std::move(dir)),
      m_width_px(width_px),
      m_height_px(height_px),
      m_available(std::system("command -v gnuplot >/dev/null 2>&1") == 0) {}

bool Plotter::plot(const std::string& name, const std::string& title, const std::string& body) {
    if (!m_available)
        return false;
    ++m_tried;
    const fs::path png = m_dir / (name + ".png");
    for (const char* term : {"pngcairo", "png"}) {
        const bool cairo = std::string(term) == "pngcairo";
        const std::string script =
            fmt::format("set terminal {} size {},{} noenhanced{}\nset output {}\nset title {}\n{}",
                        term, m_width_px, m_height_px, cairo ? " font 'sans,10'" : "",
                        gnuplotQuote(name + ".png"), gnuplotQuote(title), body);
        if (!writeText(m_dir / (name + ".gp"), script))
            return false;
        // Scripts name their data files relative to the output folder.
        const std::string cmd = "cd " + shellQuote(m_dir.string()) + " && gnuplot " +
                                shellQuote(name + ".gp") + " >/dev/null 2>&1";
        std::error_code ec;
        fs::remove(png, ec);
        if (std::system(cmd.c_str()) == 0 && fs::file_size(png, ec) > 0 && !ec) {
            m_terminal = term;
            ++m_drawn;
            return true;
        }
    }
    // gnuplot opens the output before it fails: no half-drawn figure is left to show.
    std::error_code ec;
    fs::remove(png, ec);
    return false;
}

std::string Plotter::note() const {
    if (!m_available)
        return "gnuplot not found: CSV written, no figures";
    return fmt::format("{}/{} figures drawn by gnuplot ({} terminal)", m_drawn, m_tried,
                       m_terminal.empty() ? "none" : m_terminal);
}

HtmlReport::HtmlReport(std::string_view title, std::string_view extra_css) {
    m_html = fmt::format(
        "<!doctype html>\n<html><head><meta charset='utf-8'><title>{}</title>\n<style>"
        "body{{font-family:sans-serif;max-width:1150px;margin:auto;padding:0 8px}}"
        "table{{border-collapse:collapse;margin:6px 0}}"
        "td,th{{border:1px solid #999;padding:3px 7px;text-align:right}}"
        "th{{background:#eee}}td.l,tr>th:first-child{{text-align:left}}img,video{{max-width:100%}}{"
        "}"
        "</style></head><body>\n",
        htmlEscape(title), extra_css);
}

HtmlReport& HtmlReport::heading(int level, std::string_view text) {
    m_html += fmt::format("<h{0}>{1}</h{0}>\n", level, htmlEscape(text));
    return *this;
}

HtmlReport& HtmlReport::paragraph(std::string_view text) {
    m_html += "<p>" + htmlEscape(text) + "</p>\n";
    return *this;
}

HtmlReport& HtmlReport::html(std::string_view markup) {
    m_html += markup;
    return *this;
}

HtmlReport& HtmlReport::table(const Table& t) {
    m_html += t.html();
    return *this;
}

HtmlReport& HtmlReport::image(std::string_view src, std::string_view alt, int width_px) {
    m_html += fmt::format("<img src='{}' alt='{}' width='{}'>\n", htmlEscape(src), htmlEscape(alt),
                          width_px);
    return *this;
}

HtmlReport& HtmlReport::figure(const fs::path& dir, const std::string& name,
                               const std::string& title, int width_px) {
    heading(3, title);
    std::error_code ec;
    if (fs::exists(dir / (name + ".png"), ec))
        image(name + ".png", title, width_px);
    else
        paragraph("(figure not drawn: gnuplot missing or failed; its script is " + name + ".gp)");
    return *this;
}

HtmlReport& HtmlReport::video(std::string_view src, std::string_view poster, int width_px) {
    m_html += fmt::format(
        "<video controls preload='metadata' width='{}'{}><source src='{}' type='video/mp4'>"
        "<a href='{}'>{}</a></video>\n",
        width_px, poster.empty() ? "" : " poster='" + htmlEscape(poster) + "'", htmlEscape(src),
        htmlEscape(src), htmlEscape(src));
    return *this;
}

std::string HtmlReport::str() const {
    return m_html + "</body></html>\n";
}

Status HtmlReport::write(const fs::path& path) const {
    return writeText(path, str());
}

}  // namespace qvr::report

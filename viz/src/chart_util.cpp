// SPDX-License-Identifier: MIT
// Helpers shared by viz's renderers: HTML text and page heads, tick numbers, cairo surfaces.
#include "chart_util.hpp"

#include <cairo-svg.h>
#include <cairo.h>

#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "web_assets.hpp"

namespace tgraph::viz::detail {

std::string escape(std::string_view s) {
  std::string out;
  for (char c : s) {
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
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string script_json(const nlohmann::json& j) {
  const std::string s = j.dump();
  std::string out;
  out.reserve(s.size());
  for (std::size_t i = 0; i < s.size(); ++i) {
    out += s[i];
    if (s[i] == '<' && i + 1 < s.size() && s[i + 1] == '/') out += '\\';
  }
  return out;
}

const char* const kErrorHookScript = R"js(
(function () {
  var root = document.documentElement;
  function add(m) { root.dataset.jsErrors = (root.dataset.jsErrors ? root.dataset.jsErrors + ' | ' : '') + m; }
  window.addEventListener('error', function (e) { add(String(e.message)); });
  window.addEventListener('unhandledrejection', function (e) { add(String(e.reason)); });
  var original = console.error;
  console.error = function () { add(Array.prototype.join.call(arguments, ' ')); original.apply(console, arguments); };
})();
)js";

const char* const kRenderScript = R"js(
(function () {
  const specs = JSON.parse(document.getElementById('tgraph-specs').textContent);
  const ids = Object.keys(specs);
  let done = 0;
  document.body.dataset.charts = String(ids.length);
  for (const id of ids) {
    vegaEmbed('#' + id, specs[id], {renderer: 'svg', actions: false})
      .then(function () { done += 1; document.body.dataset.chartsRendered = String(done); })
      .catch(function (err) {
        const el = document.getElementById(id);
        el.textContent = 'chart failed: ' + err;
        el.className += ' chart-error';
        console.error('tgraph chart ' + id + ': ' + err);
      });
  }
})();
)js";

std::string page_head(const std::string& title, const char* style,
                      std::initializer_list<const char*> libs) {
  std::string h = "<!doctype html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>" +
                  escape(title) + "</title><style>" + style + "</style><script>" +
                  kErrorHookScript + "</script>";
  for (const char* lib : libs) {
    h += "<script>/* ";
    h += lib;
    h += " */\n";
    h += web_asset(lib);
    h += "\n</script>";
  }
  return h + "</head><body>";
}

double tick_step(double range, int target) {
  if (range <= 0) return 1;
  const double raw = range / target;
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0, 10.0})
    if (raw <= m * mag) return m * mag;
  return 10 * mag;
}

int decimals_for(double step) {
  return step >= 1 ? 0 : static_cast<int>(std::ceil(-std::log10(step) - 1e-9));
}

void set_colour(cairo_t* cr, const std::string& hex, double alpha) {
  unsigned r = 0, g = 0, b = 0;
  if (hex.size() == 7) std::sscanf(hex.c_str() + 1, "%2x%2x%2x", &r, &g, &b);
  cairo_set_source_rgba(cr, r / 255.0, g / 255.0, b / 255.0, alpha);
}

void text_at(cairo_t* cr, double x, double y, const std::string& s, double size, double align) {
  cairo_set_font_size(cr, size);
  cairo_text_extents_t ext;
  cairo_text_extents(cr, s.c_str(), &ext);
  cairo_move_to(cr, x - ext.x_advance * align, y);
  cairo_show_text(cr, s.c_str());
}

namespace {

cairo_status_t append_bytes(void* closure, const unsigned char* data, unsigned int length) {
  static_cast<std::string*>(closure)->append(reinterpret_cast<const char*>(data), length);
  return CAIRO_STATUS_SUCCESS;
}

}  // namespace

std::string render_cairo(TimelineFormat format, double width, double height,
                         const std::function<void(cairo_t*)>& draw) {
  std::string out;
  cairo_surface_t* surface =
      format == TimelineFormat::kSvg
          ? cairo_svg_surface_create_for_stream(append_bytes, &out, width, height)
          : cairo_image_surface_create(CAIRO_FORMAT_ARGB32, static_cast<int>(width),
                                       static_cast<int>(std::ceil(height)));
  cairo_t* cr = cairo_create(surface);
  draw(cr);
  const cairo_status_t drawn = cairo_status(cr);
  cairo_destroy(cr);
  cairo_status_t written = CAIRO_STATUS_SUCCESS;
  if (format == TimelineFormat::kPng)
    written = cairo_surface_write_to_png_stream(surface, append_bytes, &out);
  cairo_surface_finish(surface);  // the SVG surface writes its document here
  const cairo_status_t finished = cairo_surface_status(surface);
  cairo_surface_destroy(surface);
  for (cairo_status_t s : {drawn, written, finished})
    if (s != CAIRO_STATUS_SUCCESS)
      throw std::runtime_error(std::string("cairo: ") + cairo_status_to_string(s));
  return out;
}

}  // namespace tgraph::viz::detail

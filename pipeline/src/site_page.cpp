// The results page (see site_page.h for why it is built this way).
#include "spherekit/pipeline/site_page.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <set>
#include <system_error>

#include "site_assets.h"
#include "site_landmarks.h"  // generated from site/viewer.js and site/style.css (CMakeLists.txt)
#include "spherekit/formats/atomic_file.h"
#include "spherekit/version.h"

namespace spherekit::pipeline {
namespace {

namespace fs = std::filesystem;

// What scripts/setup_viewer.sh leaves in DIR/dist: the two scripts the page needs, and the
// notices that go with them.
constexpr const char* kThreeScript = "three-viewer.js";
constexpr const char* kDracoScript = "draco_decoder.js";
constexpr const char* kViewerNotices[] = {"NOTICE.txt", "LICENSE-three.js.txt"};

// ---- text helpers

std::string html(const std::string& s) {
  std::string out;
  out.reserve(s.size());
  for (char c : s) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&#39;"; break;
      default: out += c;
    }
  }
  return out;
}

// A relative path as a URL (each byte outside the unreserved set percent-encoded, '/' kept),
// so that names with spaces or '#' still load, from disk or from a server.
std::string url(const std::string& path) {
  static const char* hex = "0123456789ABCDEF";
  std::string out;
  for (unsigned char c : path) {
    if (std::isalnum(c) || c == '-' || c == '.' || c == '_' || c == '~' || c == '/') {
      out += static_cast<char>(c);
    } else {
      out += '%';
      out += hex[c >> 4];
      out += hex[c & 15];
    }
  }
  return out;
}

// JSON text safe for the page: invalid UTF-8 in user-supplied names is replaced, not thrown.
std::string json_text(const Json& j) { return j.dump(-1, ' ', false, Json::error_handler_t::replace); }

std::string base64(const std::string& bytes) {
  static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const unsigned v = static_cast<unsigned char>(bytes[i]) << 16 | static_cast<unsigned char>(bytes[i + 1]) << 8 |
                       static_cast<unsigned char>(bytes[i + 2]);
    out += table[v >> 18];
    out += table[(v >> 12) & 63];
    out += table[(v >> 6) & 63];
    out += table[v & 63];
  }
  if (i < bytes.size()) {
    const bool two = i + 1 < bytes.size();
    const unsigned v = static_cast<unsigned char>(bytes[i]) << 16 | (two ? static_cast<unsigned char>(bytes[i + 1]) << 8 : 0u);
    out += table[v >> 18];
    out += table[(v >> 12) & 63];
    out += two ? table[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

// A table cell: integers as integers, other numbers with 6 significant digits.
std::string cell_text(const Json& v) {
  if (v.is_string()) return v.get<std::string>();
  if (v.is_boolean()) return v.get<bool>() ? "yes" : "no";
  if (v.is_number_integer()) return v.dump();
  if (v.is_number()) {
    const double x = v.get<double>();
    if (!std::isfinite(x)) return std::isnan(x) ? "NaN" : (x > 0 ? "inf" : "-inf");
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.6g", x);
    return buf;
  }
  if (v.is_null()) return "";
  return json_text(v);
}

// ---- reading `site` tolerantly: a wrong type counts as absent.

std::string str(const Json& j, const char* key) {
  if (!j.is_object()) return {};
  auto it = j.find(key);
  return it != j.end() && it->is_string() ? it->get<std::string>() : std::string();
}

const Json& array(const Json& j, const char* key) {
  static const Json empty = Json::array();
  if (!j.is_object()) return empty;
  auto it = j.find(key);
  return it != j.end() && it->is_array() ? *it : empty;
}

// ---- the files the page refers to

struct PageWriter {
  std::string out;                 // out_dir
  std::vector<std::string>* warnings;
  std::set<std::string> scripts;  // site/glb/*.js and site/mesh/*.js written this time

  void warn(const std::string& w) {
    if (warnings) warnings->push_back(w);
  }

  // A listed path usable in the page: relative, inside out_dir, and present. Otherwise a
  // warning and false.
  bool usable(const std::string& path, const std::string& what) {
    if (path.empty()) return false;
    const fs::path p(path);
    bool escapes = p.is_absolute() || p.has_root_name() || p.has_root_directory();
    for (const auto& part : p) escapes = escapes || part == "..";
    if (escapes) {
      warn(what + " " + path + ": not a path inside the output folder, not shown");
      return false;
    }
    std::error_code ec;
    if (!fs::is_regular_file(fs::path(out) / p, ec)) {
      warn(what + " " + path + ": no such file in " + out + ", not shown");
      return false;
    }
    return true;
  }

  Status write(const std::string& rel, const std::string& bytes) {
    std::error_code ec;
    const fs::path full = fs::path(out) / rel;
    fs::create_directories(full.parent_path(), ec);
    if (ec) return Status(ErrorCode::IoError, full.parent_path().string() + ": cannot create folder: " + ec.message());
    return formats::write_file_atomic(full.string(), bytes);
  }

  // Writes site/FOLDER/NNN_stem.js, a script calling `function`(key, "base64 of bytes"), and
  // returns its entry for data.js. The page loads it when it needs the bytes (file:// pages
  // may not fetch).
  Result<Json> script_entry(const std::string& key, const std::string& stem_of, const std::string& bytes,
                            const std::string& folder, const std::string& function) {
    std::string stem = fs::path(stem_of).stem().string();
    for (char& c : stem)
      if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_') c = '_';
    char prefix[16];
    std::snprintf(prefix, sizeof prefix, "%03zu_", scripts.size());
    const std::string script = "site/" + folder + "/" + std::string(prefix) + stem + ".js";
    scripts.insert(script);
    SPHEREKIT_RETURN_IF_ERROR(write(script, function + "(" + json_text(key) + ",\"" + base64(bytes) + "\");\n"));
    return Json{{"path", key}, {"script", script}, {"bytes", bytes.size()}};
  }

  // Writes site/glb/NNN_name.js holding the .glb at `path` and returns its entry for data.js.
  Result<Json> glb_entry(const std::string& path) {
    auto bytes = formats::read_file((fs::path(out) / path).string());
    if (!bytes.ok()) return bytes.status();
    return script_entry(path, path, bytes.value(), "glb", "spherekitGlb");
  }

  // Scripts of earlier pages that this one no longer lists.
  void remove_stale_scripts() {
    std::error_code ec;
    for (const char* folder : {"site/glb", "site/mesh"})
      for (const auto& e : fs::directory_iterator(fs::path(out) / folder, ec)) {
        const std::string rel = std::string(folder) + "/" + e.path().filename().string();
        if (e.path().extension() == ".js" && !scripts.count(rel)) fs::remove(e.path(), ec);
      }
  }
};

// Width and height of a PNG from its IHDR chunk, or {0, 0} when the bytes are not a PNG.
std::pair<int, int> png_size(const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) return {0, 0};
  unsigned char h[24] = {};
  const std::size_t n = std::fread(h, 1, sizeof h, f);
  std::fclose(f);
  static const unsigned char sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (n < 24 || !std::equal(sig, sig + 8, h) || std::string(reinterpret_cast<char*>(h + 12), 4) != "IHDR") return {0, 0};
  auto be32 = [&](int at) { return static_cast<int>(h[at] << 24 | h[at + 1] << 16 | h[at + 2] << 8 | h[at + 3]); };
  return {be32(16), be32(20)};
}

// Where scripts/setup_viewer.sh installed the viewer (its dist/ folder holds the files).
std::string viewer_root(const Json& site) {
  if (std::string dir = str(site, "viewer_dir"); !dir.empty()) return dir;
  if (const char* env = std::getenv("SPHEREKIT_VIEWER_DIR"); env && *env) return env;
  if (const char* home = std::getenv("HOME"); home && *home) return std::string(home) + "/.cache/spherekit/viewer";
  return {};
}


std::string figure_html(PageWriter& w, const Json& item, const std::string& what) {
  const std::string png = str(item, "png");
  const std::string label = str(item, "label");
  if (!w.usable(png, what)) return {};
  const auto [width, height] = png_size((fs::path(w.out) / png).string());
  std::string img = "<img src=\"" + html(url(png)) + "\" alt=\"" + html(label.empty() ? png : label) + "\"";
  std::string size_note;
  if (width > 0 && height > 0) {
    // Small images (geometry images are 65..257 texels) are shown enlarged with sharp texels.
    const int scale = width < 300 ? std::max(1, 300 / width) : 1;
    img += " width=\"" + std::to_string(width * scale) + "\" height=\"" + std::to_string(height * scale) + "\"";
    if (scale > 1) img += " class=\"pixels\"";
    size_note = " (" + std::to_string(width) + " x " + std::to_string(height) + ")";
  } else {
    w.warn(what + " " + png + ": not a PNG file");
  }
  img += ">";
  return "<figure><a href=\"" + html(url(png)) + "\">" + img + "</a><figcaption>" + html(label.empty() ? png : label) +
         size_note + "</figcaption></figure>\n";
}

std::string table_html(const Json& t) {
  std::string s = "<h3>" + html(str(t, "label")) + "</h3>\n<div class=\"table-wrap\"><table>\n";
  const Json& columns = array(t, "columns");
  if (!columns.empty()) {
    s += "<thead><tr>";
    for (const Json& c : columns) s += "<th>" + html(cell_text(c)) + "</th>";
    s += "</tr></thead>\n";
  }
  s += "<tbody>\n";
  for (const Json& row : array(t, "rows")) {
    s += "<tr>";
    if (row.is_array()) {
      for (const Json& c : row) s += std::string(c.is_number() ? "<td class=\"num\">" : "<td>") + html(cell_text(c)) + "</td>";
    } else {
      s += "<td>" + html(cell_text(row)) + "</td>";
    }
    s += "</tr>\n";
  }
  return s + "</tbody></table></div>\n";
}

}  // namespace

Status write_site_page(const std::string& out_dir, const Json& site, std::vector<std::string>* warnings) {
  if (!site.is_object()) return Status(ErrorCode::InvalidArgument, "the results page description is not a JSON object");
  PageWriter w{out_dir, warnings, {}};
  try {
    const std::string title = str(site, "title").empty() ? "SphereKit results" : str(site, "title");

    // The viewer's third-party scripts, copied into the page's folder so it is self-contained.
    const std::string root = viewer_root(site);
    const fs::path dist = fs::path(root) / "dist";
    std::string no_viewer;  // why there is no 3-D view (empty: there is one)
    std::string viewer_versions;
    std::error_code ec;
    if (root.empty()) {
      no_viewer = "no viewer folder is known (HOME and SPHEREKIT_VIEWER_DIR are unset)";
    } else if (!fs::is_regular_file(dist / kThreeScript, ec) || !fs::is_regular_file(dist / kDracoScript, ec)) {
      no_viewer = "three.js and the Draco decoder are not installed in " + dist.string() +
                  " (run bash scripts/setup_viewer.sh: it needs node and npm)";
    } else {
      for (const char* name : {kThreeScript, kDracoScript}) {
        auto bytes = formats::read_file((dist / name).string());
        if (!bytes.ok()) return bytes.status();
        SPHEREKIT_RETURN_IF_ERROR(w.write(std::string("site/lib/") + name, bytes.value()));
      }
      for (const char* name : kViewerNotices) {
        auto bytes = formats::read_file((dist / name).string());
        if (bytes.ok()) SPHEREKIT_RETURN_IF_ERROR(w.write(std::string("site/lib/") + name, bytes.value()));
      }
      if (auto stamp = formats::read_file((dist / "STAMP").string()); stamp.ok()) {
        viewer_versions = stamp.value();
        while (!viewer_versions.empty() && std::isspace(static_cast<unsigned char>(viewer_versions.back())))
          viewer_versions.pop_back();
      }
    }
    const bool viewer = no_viewer.empty();
    if (!viewer) w.warn("results page: no 3-D view: " + no_viewer);

    // The glTF files, as scripts (only with a viewer: nothing else reads them).
    Json data_models = Json::array();
    std::vector<std::string> model_names;  // of data_models, for the selector
    for (const Json& m : array(site, "models")) {
      const std::string name = str(m, "name").empty() ? "model " + std::to_string(model_names.size() + 1) : str(m, "name");
      Json lods = Json::array();
      for (const Json& lod : array(m, "lods")) {
        if (!lod.is_string() || !w.usable(lod.get<std::string>(), name + " level of detail")) continue;
        if (!viewer) continue;
        SPHEREKIT_ASSIGN_OR_RETURN(Json entry, w.glb_entry(lod.get<std::string>()));
        lods.push_back(std::move(entry));
      }
      if (lods.empty()) continue;
      data_models.push_back({{"name", name}, {"lods", std::move(lods)}});
      model_names.push_back(name);
    }
    std::vector<Json> morph_items;
    if (const auto it = site.find("morph"); it != site.end()) {
      if (it->is_object()) morph_items.push_back(*it);
      if (it->is_array())
        for (const Json& m : *it) morph_items.push_back(m);
    }
    Json data_morphs = Json::array();
    for (const Json& m : morph_items) {
      const std::string glb = str(m, "glb");
      if (!w.usable(glb, "morph") || !viewer) continue;
      SPHEREKIT_ASSIGN_OR_RETURN(Json entry, w.glb_entry(glb));
      data_morphs.push_back({{"label", str(m, "label").empty() ? glb : str(m, "label")},
                             {"mode", str(m, "mode") == "weights" ? "weights" : "sequence"},
                             {"glb", std::move(entry)}});
    }

    // The landmark editor (issue 25): each member's mesh as read, with its feature file.
    Json data_landmarks = Json::array();
    static const Json no_landmarks;
    const auto landmarks_it = site.find("landmarks");
    const Json& landmark_members = array(landmarks_it != site.end() ? *landmarks_it : no_landmarks, "members");
    for (const Json& m : landmark_members) {
      if (!viewer) break;
      auto member = detail::landmark_member_data(m);
      if (!member.ok()) {
        w.warn("landmarks: " + member.status().message() + ", not shown");
        continue;
      }
      SPHEREKIT_ASSIGN_OR_RETURN(Json script, w.script_entry("mesh:" + member->entry["name"].get<std::string>(),
                                                             member->entry["name"].get<std::string>() + ".mesh",
                                                             member->payload, "mesh", "spherekitMesh"));
      member->entry["mesh"] = std::move(script);
      data_landmarks.push_back(std::move(member->entry));
    }

    // ---- index.html
    std::string body;
    const bool models_3d = viewer && !data_models.empty();
    const bool morphs_3d = viewer && !data_morphs.empty();
    std::string nav;
    auto add_nav = [&](const std::string& id, const std::string& text) {
      nav += "<a href=\"#" + id + "\">" + html(text) + "</a>";
    };

    const bool any_3d_listed = !array(site, "models").empty() || !morph_items.empty() || !landmark_members.empty();
    if (!viewer && any_3d_listed) {
      add_nav("models", "3-D models");
      body += "<section id=\"models\"><h2>3-D models</h2>\n<p class=\"note\" id=\"no-viewer\">No 3-D view: " +
              html(no_viewer) + ". The images and tables below do not need it.</p></section>\n";
    }
    if (models_3d) {
      add_nav("models", "3-D models");
      body += "<section id=\"models\"><h2>3-D models</h2>\n<div class=\"viewer\" id=\"model-viewer\">\n"
              "<div class=\"toolbar\"><label>model <select id=\"model-select\">";
      for (std::size_t i = 0; i < model_names.size(); ++i)
        body += "<option value=\"" + std::to_string(i) + "\">" + html(model_names[i]) + "</option>";
      if (model_names.size() > 1) body += "<option value=\"all\">all, side by side</option>";
      body += "</select></label><span id=\"lod-buttons\"></span>"
              "<label><input type=\"checkbox\" id=\"wireframe\"> wireframe</label>"
              "<label title=\"one labelled grid over the octahedral geometry-image domain (TEXCOORD_0): the same "
              "cell is the same sphere point, and in a consistent collection the same feature, on every model\">"
              "<input type=\"checkbox\" id=\"shared-texture\"> shared texture</label>"
              "<label title=\"each model on its sphere: the sphere point of every vertex, from TEXCOORD_0\">"
              "<input type=\"checkbox\" id=\"on-sphere\"> on its sphere</label></div>\n"
              "<div class=\"canvas-box\" id=\"model-canvas\"></div>\n"
              "<p class=\"status\" id=\"model-status\">loading the 3-D view...</p>\n"
              "<noscript><p class=\"note\">The 3-D view needs JavaScript.</p></noscript>\n"
              "<p class=\"status\">Drag to turn, scroll to zoom, right-drag to pan. LOD 0 is the finest level; "
              "\"auto\" picks coarser levels as the model gets smaller on screen. \"shared texture\" paints one grid "
              "through the common domain: in a consistent collection each cell lands on the same part of every "
              "model (compare them with \"all, side by side\").</p></div></section>\n";
    }
    if (viewer && !data_landmarks.empty()) {
      add_nav("landmarks", "landmarks");
      body += "<section id=\"landmarks\"><h2>Landmarks</h2>\n<div class=\"viewer\" id=\"landmark-viewer\">\n"
              "<div class=\"toolbar\"><label>member <select id=\"landmark-member\">";
      for (std::size_t i = 0; i < data_landmarks.size(); ++i)
        body += "<option value=\"" + std::to_string(i) + "\">" + html(data_landmarks[i]["name"].get<std::string>()) +
                "</option>";
      body += "</select></label>"
              "<button type=\"button\" id=\"landmark-download\">download .lm.txt</button>"
              "<button type=\"button\" id=\"landmark-download-all\">download all</button>"
              "<label><input type=\"checkbox\" id=\"landmark-labels\" checked> labels</label>"
              "<label><input type=\"checkbox\" id=\"landmark-wireframe\"> edges</label></div>\n"
              "<div class=\"canvas-box\" id=\"landmark-canvas\"></div>\n"
              "<p class=\"status\" id=\"landmark-status\">loading the landmarks...</p>\n"
              "<p class=\"status\" id=\"landmark-source\"></p>\n"
              "<ol class=\"landmark-list\" id=\"landmark-list\"></ol>\n"
              "<p class=\"status\">Each member is shown as its own input mesh (not a remesh), so the vertex numbers "
              "are the ones its <code>.lm.txt</code> file uses. Click the surface to place a landmark at the nearest "
              "vertex; click a landmark's \"move\" and then the surface to move it; edit a name to rename it. "
              "The consistent collection needs the same names on every member. \"download\" saves the member's "
              "<code>NAME.lm.txt</code> (lines <code>name vertex_index</code>); put it beside the mesh and rerun, or "
              "check it with <code>spherekit check MESH --landmarks NAME.lm.txt</code>.</p></div></section>\n";
    }
    if (morphs_3d) {
      add_nav("morphs", "morphs");
      body += "<section id=\"morphs\"><h2>Morphs</h2>\n";
      for (std::size_t k = 0; k < data_morphs.size(); ++k) {
        const std::string n = std::to_string(k);
        body += "<div class=\"viewer morph\"><h3>" + html(data_morphs[k]["label"].get<std::string>()) +
                "</h3>\n<div class=\"toolbar\" id=\"morph-controls-" + n + "\"></div>\n<div class=\"canvas-box\" id=\"morph-canvas-" +
                n + "\"></div>\n<p class=\"status\" id=\"morph-status-" + n + "\">loading...</p></div>\n";
      }
      body += "</section>\n";
    }
    std::string plots;
    for (const Json& p : array(site, "plots")) plots += figure_html(w, p, "plot");
    if (!plots.empty()) {
      add_nav("plots", "plots");
      body += "<section id=\"plots\"><h2>Plots</h2>\n<div class=\"figures\">\n" + plots + "</div></section>\n";
    }
    std::string images;
    for (const Json& m : array(site, "models")) {
      std::string figures;
      for (const Json& i : array(m, "images")) figures += figure_html(w, i, str(m, "name") + " image");
      if (!figures.empty()) images += "<h3>" + html(str(m, "name")) + "</h3>\n<div class=\"figures\">\n" + figures + "</div>\n";
    }
    if (!images.empty()) {
      add_nav("images", "images");
      body += "<section id=\"images\"><h2>Images</h2>\n" + images + "</section>\n";
    }
    std::string tables;
    for (const Json& t : array(site, "tables")) tables += table_html(t);
    if (!tables.empty()) {
      add_nav("tables", "tables");
      body += "<section id=\"tables\"><h2>Tables</h2>\n" + tables + "</section>\n";
    }

    std::string page = "<!doctype html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n"
                       "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
                       // No favicon request: a server without one would log a 404 in the console.
                       "<link rel=\"icon\" href=\"data:,\">\n<title>" +
                       html(title) + "</title>\n<style>" + kSiteStyleCss + "</style></head>\n<body>\n<header><h1>" + html(title) +
                       "</h1>\n";
    if (const std::string d = str(site, "description"); !d.empty()) page += "<p>" + html(d) + "</p>\n";
    page += "<nav>" + nav + "</nav></header>\n<main>\n" + body + "</main>\n<footer>Written by spherekit " +
            std::string(kVersion) + ".";
    if (viewer)
      page += " 3-D view: " + html(viewer_versions.empty() ? "three.js" : viewer_versions) +
              " and Google's Draco decoder (<a href=\"site/lib/NOTICE.txt\">notices</a>).";
    page += "</footer>\n";
    if (models_3d || morphs_3d || (viewer && !data_landmarks.empty())) {
      SPHEREKIT_RETURN_IF_ERROR(w.write("site/data.js", "window.SPHEREKIT_SITE = " +
                                                            json_text(Json{{"title", title},
                                                                           {"models", data_models},
                                                                           {"morphs", data_morphs},
                                                                           {"landmarks", data_landmarks}}) +
                                                            ";\n"));
      SPHEREKIT_RETURN_IF_ERROR(w.write("site/viewer.js", kSiteViewerJs));
      SPHEREKIT_RETURN_IF_ERROR(w.write("site/landmarks.js", kSiteLandmarksJs));
      page += "<script src=\"site/lib/three-viewer.js\"></script>\n<script src=\"site/lib/draco_decoder.js\"></script>\n"
              "<script src=\"site/data.js\"></script>\n<script src=\"site/viewer.js\"></script>\n"
              "<script src=\"site/landmarks.js\"></script>\n";
    }
    page += "</body></html>\n";
    w.remove_stale_scripts();
    // Last, so that the page never lists a file that is not written yet.
    return w.write("index.html", page);
  } catch (const std::exception& e) {
    // nlohmann::json or std::filesystem threw: a bug here, reported rather than crashing.
    return Status(ErrorCode::Internal, std::string("results page: ") + e.what());
  }
}

}  // namespace spherekit::pipeline

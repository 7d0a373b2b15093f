"""The cohort's QC report: one HTML page (no network) with a sortable group
table that flags outliers and shows each row's warnings and trust flags, a
filter for flagged rows, a pass/fail rating per row exported as TSV, and
per job (one run of `dynsub segment`: an image's structures segmented
together) each structure's slices with the contour, its
3D view, its convergence plot and its numbers, and an interactive view
(NiiVue: the image with the labelmap on three planes and the surfaces in 3D). The figures and the
views' data stay separate files beside it, loaded as they scroll into view
or when a view is opened, so that the page of a large cohort opens at
once; a copy of the page needs its folder.

Ratings are kept in the browser (localStorage, per page address) until
exported: "export ratings" saves qc_ratings.tsv with participant_id,
session_id, structure, rating (pass, fail or n/a) and flags.

Flags (the reasons a row is marked for a look):
  failed       the job did not complete;
  warnings     dynsub warned (a collapse, a leak, landmarks far from edges, a seed region that leaked);
  untrusted    report.json's trust flags say not to trust the result (one click alone, a result
               small against its clicks or atlas, atlas and clicks or result apart, a leak);
  volume       the volume is more than 3 robust standard deviations (1.4826 MAD) from the
               median of the same structure, judged only with at least 4 of that structure;
  residual     the rms distance of the landmarks to the surface exceeds 1 mm (twice the
               default landmark tolerance: the surface did not come to the clicks).
"""
import filecmp
import html
import math
import os
import shutil
import statistics
import struct

import dynsub_bids as bids

RESIDUAL_LIMIT_MM = 1.0
ROBUST_Z_LIMIT = 3.0
MIN_FOR_VOLUME_FLAG = 4


def _number(value):
    try:
        return float(value)
    except (TypeError, ValueError):
        return None


def _png_size(path):
    """A PNG's width and height (its IHDR chunk), or None for another file."""
    with open(path, "rb") as f:
        head = f.read(24)
    if len(head) < 24 or head[:8] != b"\x89PNG\r\n\x1a\n" or head[12:16] != b"IHDR":
        return None
    return struct.unpack(">II", head[16:24])


def _image(path, alt, page):
    """The figure at path, by its path relative to the page; a link to it
    when scripts are off. Its size is given, so that the page is laid out
    once, before the figures load, instead of moving as each arrives."""
    if not os.path.exists(path):
        return f'<p class="missing">{html.escape(alt)}: not rendered</p>'
    source = html.escape(os.path.relpath(path, os.path.dirname(page)))
    size = _png_size(path)
    dimensions = f' width="{size[0]}" height="{size[1]}"' if size else ""
    return (f'<a class="figure" href="{source}"><img src="{source}"{dimensions} loading="lazy" '
            f'alt="{html.escape(alt)}"></a>')


def _rms_residual(report):
    distances = [r["distance_mm"] for r in report.get("landmark_residuals", []) if "distance_mm" in r]
    return math.sqrt(sum(d * d for d in distances) / len(distances)) if distances else None


def flagged_rows(jobs, out):
    rows = bids.group_rows(jobs, out)
    for row in rows:
        row["flags"] = []
        row["rms_residual_mm"] = None
        if row["status"] != "ok":
            row["flags"].append("failed")
            continue
        report = row["report"]
        row["rms_residual_mm"] = _rms_residual(report)
        if report.get("warnings"):
            row["flags"].append("warnings")
        if report.get("trust", {}).get("flags"):
            row["flags"].append("untrusted")
        if row["rms_residual_mm"] is not None and row["rms_residual_mm"] > RESIDUAL_LIMIT_MM:
            row["flags"].append("residual")
    by_structure = {}
    for row in rows:
        if row["status"] == "ok":
            by_structure.setdefault(row["structure"], []).append(row)
    for group in by_structure.values():
        volumes = [_number(r["volume_mm3"]) for r in group]
        if len(volumes) < MIN_FOR_VOLUME_FLAG:
            continue
        median = statistics.median(volumes)
        spread = 1.4826 * statistics.median(abs(v - median) for v in volumes)
        for row, volume in zip(group, volumes):
            row["volume_z"] = (volume - median) / spread if spread > 0 else 0.0
            if abs(row["volume_z"]) > ROBUST_Z_LIMIT:
                row["flags"].append("volume")
    return rows


STYLE = """
body { font-family: sans-serif; margin: 1.5em; color: #222; }
table { border-collapse: collapse; font-size: 0.9em; }
th, td { border: 1px solid #bbb; padding: 0.25em 0.5em; text-align: right; }
th { background: #eee; cursor: pointer; user-select: none; }
th[aria-sort="ascending"]::after { content: " \\25B2"; }
th[aria-sort="descending"]::after { content: " \\25BC"; }
td.text { text-align: left; }
tr.flagged td { background: #fde2e2; }
.flag { display: inline-block; background: #c0392b; color: white; border-radius: 3px; padding: 0 0.3em;
        margin-right: 0.2em; font-size: 0.85em; }
section { border-top: 2px solid #ccc; margin-top: 2em; padding-top: 0.5em; }
div.figures { display: flex; gap: 1%; align-items: flex-start; }
div.figures > * { flex: 1; }
a.figure img { width: 100%; height: auto; border: 1px solid #ddd; cursor: zoom-in; }
dialog { padding: 0; border: none; max-width: 95vw; max-height: 95vh; }
dialog img { max-width: 95vw; max-height: 95vh; display: block; cursor: zoom-out; }
dialog::backdrop { background: rgba(0, 0, 0, 0.7); }
dialog.live { padding: 0.5em; background: #111; color: #eee; }
dialog.live div.canvas { width: 90vw; height: 75vh; }
dialog.live p { margin: 0.3em 0; }
td.rating select { font-size: 0.9em; }
td.notes { text-align: left; max-width: 30em; font-size: 0.85em; }
.missing { color: #888; font-style: italic; }
dl { display: grid; grid-template-columns: max-content auto; gap: 0.1em 1em; }
dt { font-weight: bold; }
"""

# Sorting by a column's text, or numerically when every cell is a number or
# n/a; the flagged-rows filter (also set by the address's #flagged); a figure
# enlarged in a dialog on click.
SCRIPT = """
var filter = document.getElementById("only-flagged");
function applyFilter() {
  document.querySelectorAll("#group tbody tr").forEach(function (row) {
    row.hidden = filter.checked && !row.classList.contains("flagged");
  });
}
filter.addEventListener("change", applyFilter);
function filterFromAddress() {
  if (location.hash === "#flagged") { filter.checked = true; applyFilter(); }
}
window.addEventListener("hashchange", filterFromAddress);
applyFilter();
filterFromAddress();
var viewer = document.getElementById("viewer"), large = viewer.querySelector("img");
document.querySelectorAll("a.figure").forEach(function (link) {
  link.addEventListener("click", function (event) {
    event.preventDefault();
    large.src = link.getAttribute("href");
    large.alt = link.querySelector("img").alt;
    viewer.showModal();
  });
});
viewer.addEventListener("click", function () { viewer.close(); });
var store = "dynsub-qc " + location.pathname, ratings = {};
try { ratings = JSON.parse(localStorage.getItem(store) || "{}"); } catch (error) { ratings = {}; }
// A row is a structure in one T1w: a participant's runs and acquisitions are rated apart.
function rowKey(row) {
  var d = row.dataset;
  return [d.participant, d.session, d.structure, d.t1w].join("\\t");
}
document.querySelectorAll("#group tbody tr").forEach(function (row) {
  var select = row.querySelector("td.rating select"), cell = select.parentNode;
  select.value = ratings[rowKey(row)] || "";
  cell.setAttribute("data-value", select.value || "n/a");
  select.addEventListener("change", function () {
    if (select.value) { ratings[rowKey(row)] = select.value; } else { delete ratings[rowKey(row)]; }
    cell.setAttribute("data-value", select.value || "n/a");
    try { localStorage.setItem(store, JSON.stringify(ratings)); } catch (error) { /* kept for this visit only */ }
  });
});
document.getElementById("export").addEventListener("click", function () {
  var lines = ["participant_id\tsession_id\tstructure\trating\tflags\tt1w"];
  document.querySelectorAll("#group tbody tr").forEach(function (row) {
    var rating = row.querySelector("td.rating select").value || "n/a";
    var d = row.dataset;
    lines.push([d.participant, d.session, d.structure, rating, d.flags || "n/a", d.t1w].join("\\t"));
  });
  var link = document.createElement("a");
  link.href = URL.createObjectURL(new Blob([lines.join("\\n") + "\\n"], {type: "text/tab-separated-values"}));
  link.download = "qc_ratings.tsv";
  document.body.appendChild(link);
  link.click();
  link.remove();
});
var live = document.getElementById("live"), shown = null;
function loadScript(source) {
  return new Promise(function (resolve, reject) {
    var script = document.createElement("script");
    script.src = source;
    script.onload = resolve;
    script.onerror = function () { script.remove(); reject(new Error("cannot load " + source)); };
    document.head.appendChild(script);
  });
}
function bytes(text) { return Uint8Array.from(atob(text), function (c) { return c.charCodeAt(0); }).buffer; }
async function openView(button) {
  var status = live.querySelector("p.status"), key = button.dataset.key;
  live.removeAttribute("data-drawn");
  status.textContent = "loading " + button.dataset.title + "...";
  live.showModal();
  try {
    if (!window.niivue) { await loadScript(live.dataset.niivue); }
    if (!(window.dynsubViews && window.dynsubViews[key])) { await loadScript(button.dataset.view); }
    var data = window.dynsubViews[key], canvas = document.createElement("canvas");
    live.querySelector("div.canvas").replaceChildren(canvas);
    var nv = new niivue.Niivue({backColor: [0, 0, 0, 1], crosshairColor: [0, 0.6, 1, 1], show3Dcrosshair: true,
                                isColorbar: false,
                                multiplanarShowRender: niivue.SHOW_RENDER.ALWAYS, meshThicknessOn2D: 0.5,
                                meshXRay: 0.6});
    shown = nv;
    await nv.attachToCanvas(canvas);
    nv.addVolume(await niivue.NVImage.loadFromBase64({base64: data.image, name: key + "_image.nii.gz"}));
    nv.addVolume(await niivue.NVImage.loadFromBase64({base64: data.labels, name: key + "_labels.nii.gz",
                                                      colormap: "red", opacity: 0.4, cal_min: 0, cal_max: 1}));
    nv.addMesh(new niivue.NVMesh(new Float32Array(bytes(data.points)), new Uint32Array(bytes(data.triangles)),
                                 key + "_surface", new Uint8Array([255, 200, 0, 255]), 1, true, nv.gl));
    nv.setSliceType(nv.sliceTypeMultiplanar);
    nv.drawScene();
    status.textContent = button.dataset.title;
    live.setAttribute("data-drawn", key);
  } catch (error) {
    status.textContent = button.dataset.title + ": the view could not be opened (" + error.message + ")";
    console.error("QC view " + key + ": " + error.message);
  }
}
function closeView() {
  if (shown && shown.gl) {
    var lose = shown.gl.getExtension("WEBGL_lose_context");
    if (lose) { lose.loseContext(); }
  }
  shown = null;
  live.querySelector("div.canvas").replaceChildren();
}
document.querySelectorAll("button.view").forEach(function (button) {
  button.addEventListener("click", function () { openView(button); });
});
live.querySelector("button.close").addEventListener("click", function () { live.close(); });
live.addEventListener("close", closeView);
document.querySelectorAll("table.sortable th").forEach(function (header, column) {
  header.addEventListener("click", function () {
    var table = header.closest("table"), body = table.tBodies[0];
    var rows = Array.prototype.slice.call(body.rows);
    var ascending = header.getAttribute("aria-sort") !== "ascending";
    table.querySelectorAll("th").forEach(function (h) { h.removeAttribute("aria-sort"); });
    header.setAttribute("aria-sort", ascending ? "ascending" : "descending");
    var key = function (row) { return row.cells[column].getAttribute("data-value") || row.cells[column].textContent; };
    var numeric = rows.every(function (r) { var k = key(r); return k === "n/a" || !isNaN(parseFloat(k)); });
    rows.sort(function (a, b) {
      var x = key(a), y = key(b), order;
      if (numeric) {
        x = x === "n/a" ? -Infinity : parseFloat(x); y = y === "n/a" ? -Infinity : parseFloat(y);
        order = x - y;
      } else { order = x.localeCompare(y); }
      return ascending ? order : -order;
    });
    rows.forEach(function (r) { body.appendChild(r); });
  });
});
"""

COLUMNS = [("participant_id", "subject", True), ("session_id", "session", True), ("structure", "structure", True),
           ("status", "status", True), ("volume_mm3", "volume (mm³)", False),
           ("volume_z", "volume robust z", False), ("dice", "Dice", False), ("hd95_mm", "HD95 (mm)", False),
           ("rms_residual_mm", "landmark rms (mm)", False), ("control_vertices", "control vertices", False),
           ("seconds", "seconds", False), ("flags", "flags", True), ("notes", "warnings and trust", True),
           ("rating", "rating", True)]


def _cell(row, key, text):
    value = row.get(key)
    if key == "rating":  # set from the browser's saved ratings by the page's script
        return ('<td class="rating text"><select aria-label="rating"><option value="">—</option>'
                '<option value="pass">pass</option><option value="fail">fail</option></select></td>')
    if key == "notes":
        notes = [n for n in (row.get("trust_flags"), row.get("warnings")) if n not in (None, "", "n/a")]
        return f'<td class="notes">{html.escape("; ".join(notes))}</td>'
    if key == "flags":
        shown = "".join(f'<span class="flag">{html.escape(f)}</span>' for f in value) or "—"
        return f'<td class="text" data-value="{len(value)}">{shown}</td>'
    if isinstance(value, float):
        value = f"{value:.2f}"
    value = "n/a" if value in (None, "") else str(value)
    if key == "structure" and row["status"] == "ok":
        anchor = row["job"].name
        return f'<td class="text" data-value="{html.escape(value)}"><a href="#{anchor}">{html.escape(value)}</a></td>'
    return f'<td class="{"text" if text else "num"}">{html.escape(value)}</td>'


def _structure_facts(row, out, page, headed):
    """One structure's figures and numbers on its job's section (headed by
    its name when the job has several)."""
    job, report = row["job"], row["report"]
    figures = bids.figure_paths(out, job.dir, job.stem, row["structure"])
    parts = [f'<h3>{html.escape(row["structure"])}</h3>'] if headed else []
    parts += ['<div class="figures">',
              _image(figures["slices"], "slices with the contour (green on an image edge, magenta 3 mm or more "
                     "from any)", page),
              _image(figures["surface3d"], "3D view, coloured the same way", page),
              _image(figures["convergence"], "convergence", page), "</div>"]
    facts = [("flags", ", ".join(row["flags"]) or "none"), ("volume (mm³)", row["volume_mm3"]),
             ("Dice", row["dice"]), ("mean surface distance (mm)", row["mean_surface_distance_mm"]),
             ("control vertices", row["control_vertices"]), ("steps", row["iterations"]),
             ("seconds", row["seconds"]), ("landmarks", report.get("landmark_count")),
             ("start", report.get("init")), ("surface on edges", report.get("surface_on_edges", "n/a"))]
    shown = [(k, f"{v:.3g}" if isinstance(v, float) else v) for k, v in facts]
    parts.append("<dl>" + "".join(f"<dt>{html.escape(k)}</dt><dd>{html.escape(str(v))}</dd>" for k, v in shown))
    for flag in report.get("trust", {}).get("flags", []):
        parts.append(f"<dt>not to trust ({html.escape(flag['name'])})</dt><dd>{html.escape(flag['message'])}</dd>")
    for warning in report.get("warnings", []):
        parts.append(f"<dt>warning</dt><dd>{html.escape(warning)}</dd>")
    parts.append("</dl>")
    return parts


def _install_niivue(niivue, out):
    """NiiVue's browser build copied into OUT/viewer (when it changed); its
    path relative to the page, or None without it."""
    if not niivue or not os.path.isfile(niivue):
        return None
    target = os.path.join(out, "viewer", "niivue.umd.js")
    if not (os.path.exists(target) and filecmp.cmp(niivue, target, shallow=False)):
        os.makedirs(os.path.dirname(target), exist_ok=True)
        shutil.copyfile(niivue, target + ".tmp")
        os.replace(target + ".tmp", target)
    return "viewer/niivue.umd.js"


def write_report(jobs, out, path, niivue=None):
    """Writes the page to path (by a rename) and returns its rows. niivue is
    NiiVue's niivue.umd.js, copied beside the page for the interactive views;
    without it the page says how to get them."""
    rows = flagged_rows(jobs, out)
    viewer_script = _install_niivue(niivue, out)
    flagged = sum(1 for r in rows if r["flags"])
    parts = ["<!DOCTYPE html>", '<html lang="en"><head><meta charset="utf-8">',
             "<title>DynSub QC report</title>", f"<style>{STYLE}</style></head><body>",
             "<h1>DynSub QC report</h1>",
             f"<p>{len(rows)} structures segmented, {sum(r['status'] == 'ok' for r in rows)} complete, "
             f"{flagged} flagged. Click a column header to sort; click a structure for its figures, "
             "a figure to enlarge it. Rate each row pass or fail; ratings stay in this browser until "
             "exported.</p>",
             '<p><label><input type="checkbox" id="only-flagged"> flagged rows only</label> '
             '(<a href="#flagged">link</a>) <button type="button" id="export">export ratings (TSV)</button></p>',
             '<table class="sortable" id="group"><thead><tr>']
    parts += [f"<th>{html.escape(title)}</th>" for _, title, _ in COLUMNS]
    parts.append("</tr></thead><tbody>")
    for row in rows:
        data = {"participant": row["participant_id"], "session": row["session_id"], "structure": row["structure"],
                "t1w": row["t1w"], "flags": ",".join(row["flags"])}
        parts.append(f'<tr class="{"flagged" if row["flags"] else ""}" '
                     + " ".join(f'data-{k}="{html.escape(v)}"' for k, v in data.items()) + ">")
        parts += [_cell(row, key, text) for key, _, text in COLUMNS]
        parts.append("</tr>")
    parts.append("</tbody></table>")
    parts.append("<p>Flags: <b>failed</b> the job did not complete; <b>warnings</b> dynsub warned; "
                 "<b>untrusted</b> report.json's trust flags say not to trust the result; "
                 f"<b>volume</b> more than {ROBUST_Z_LIMIT:g} robust SD from the structure's median "
                 f"(with at least {MIN_FOR_VOLUME_FLAG} of it); <b>residual</b> landmarks more than "
                 f"{RESIDUAL_LIMIT_MM:g} mm rms from the surface.</p>")
    by_job = {}
    for row in rows:
        by_job.setdefault(row["job"].key, []).append(row)
    for job_rows in by_job.values():
        job = job_rows[0]["job"]
        session = job_rows[0]["session_id"]
        title = (f'{job_rows[0]["participant_id"]} {session if session != "n/a" else ""} '
                 + ", ".join(r["structure"] for r in job_rows))
        parts.append(f'<section id="{html.escape(job.name)}"><h2>{html.escape(title)}</h2>')
        if job_rows[0]["status"] != "ok":
            parts.append(f'<p><span class="flag">{html.escape(job_rows[0]["status"])}</span> '
                         f'{html.escape(job_rows[0]["message"])}</p></section>')
            continue
        view = bids.view_path(out, job.dir, job.stem, job.desc)
        if not viewer_script:
            parts.append('<p class="missing">interactive view: NiiVue is not installed (./run build installs it '
                         "into build/niivue)</p>")
        elif not os.path.exists(view):
            parts.append('<p class="missing">interactive view: its data was not written (see the job\'s log)</p>')
        else:
            parts.append(f'<p><button type="button" class="view" data-key="{html.escape(job.name)}" '
                         f'data-title="{html.escape(title)}" '
                         f'data-view="{html.escape(os.path.relpath(view, os.path.dirname(path)))}">'
                         "interactive view</button></p>")
        for row in job_rows:
            parts += _structure_facts(row, out, path, len(job_rows) > 1)
        parts.append("</section>")
    parts.append('<dialog id="viewer"><img alt=""></dialog>')
    parts.append(f'<dialog id="live" class="live" data-niivue="{html.escape(viewer_script or "")}">'
                 '<p class="status"></p><div class="canvas"></div>'
                 "<p>Red: the labelmap; yellow: the fitted surfaces (their trace on the planes). Click a plane to "
                 "move the crosshair; drag in 3D to turn. Coordinates are the image's RAS.</p>"
                 '<p><button type="button" class="close">close</button></p></dialog>')
    parts.append(f"<script>{SCRIPT}</script></body></html>")
    bids.write_by_rename(path, "\n".join(parts) + "\n")
    return rows

"""The site's two static files: its style sheet and the table sorter, written beside the pages
(``site.css`` and ``sort.js``) and linked relatively, so that pages opened from disk
(``file://``) need no server and no network."""

from __future__ import annotations

CSS_NAME = "site.css"
JS_NAME = "sort.js"

CSS = """\
body { font: 15px/1.45 system-ui, sans-serif; margin: 1.5em auto; max-width: 75em;
       padding: 0 1em; color: #222; }
nav { margin-bottom: 1em; font-size: 0.9em; }
nav a { margin-right: 1em; }
h1 { font-size: 1.5em; } h2 { font-size: 1.25em; margin-top: 1.6em; }
h3 { font-size: 1.05em; margin-top: 1.3em; }
table { border-collapse: collapse; margin: 0.5em 0; font-size: 0.85em; }
th, td { border: 1px solid #ccc; padding: 0.2em 0.5em; vertical-align: top; }
td { white-space: nowrap; } table#experiments td { white-space: normal; }
table#experiments td:nth-child(3) { min-width: 30em; }
th { background: #f2f2f2; }
table.sortable th { cursor: pointer; user-select: none; }
table.sortable th[aria-sort="ascending"]::after { content: " \\25B2"; }
table.sortable th[aria-sort="descending"]::after { content: " \\25BC"; }
td.num { text-align: right; font-variant-numeric: tabular-nums; }
.scroll { overflow-x: auto; }
.legend { font-size: 0.85em; color: #444; }
.legend dt { font-family: monospace; display: inline; }
.legend dd { display: inline; margin: 0 0 0 0.3em; }
.legend div { margin: 0.1em 0; }
.source, .note { font-size: 0.85em; color: #555; }
.warning { color: #a40; font-weight: bold; }
figure { margin: 1em 0; } figure img { max-width: 100%; border: 1px solid #ddd; }
figcaption { font-size: 0.85em; color: #555; }
tr.change-point td { background: #fde8d8; }
li.change-point { color: #a40; }
code { font-size: 0.95em; }
"""

JS = """\
// Sort a table.sortable by the clicked column: numbers by value, the rest as text.
(function () {
  function key(cell) {
    var text = cell.getAttribute("data-value");
    if (text === null) { text = cell.textContent.trim(); }
    var number = parseFloat(text.replace(/[\\u00d7,]/g, ""));
    return { text: text, number: isNaN(number) || !/^[-+.\\d]/.test(text) ? null : number };
  }
  function sortBy(table, column, th) {
    var body = table.tBodies[0];
    var rows = Array.prototype.slice.call(body.rows);
    var ascending = th.getAttribute("aria-sort") !== "ascending";
    rows.sort(function (a, b) {
      var x = key(a.cells[column]), y = key(b.cells[column]);
      var order;
      if (x.number !== null && y.number !== null) { order = x.number - y.number; }
      else if (x.number !== null) { order = -1; }
      else if (y.number !== null) { order = 1; }
      else { order = x.text.localeCompare(y.text); }
      return ascending ? order : -order;
    });
    rows.forEach(function (row) { body.appendChild(row); });
    Array.prototype.forEach.call(th.parentNode.cells, function (other) {
      other.removeAttribute("aria-sort");
    });
    th.setAttribute("aria-sort", ascending ? "ascending" : "descending");
  }
  document.addEventListener("DOMContentLoaded", function () {
    document.querySelectorAll("table.sortable").forEach(function (table) {
      if (!table.tHead || !table.tBodies.length) { return; }
      Array.prototype.forEach.call(table.tHead.rows[0].cells, function (th, column) {
        th.addEventListener("click", function () { sortBy(table, column, th); });
      });
    });
  });
})();
"""

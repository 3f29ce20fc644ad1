"""The HTML report's inline style sheet (kept apart so html.py reads as structure)."""

CSS = """
:root { --error: #c62828; --warning: #b26a00; --info: #1565c0; --ok: #2e7d32; }
body { font: 14px/1.45 system-ui, sans-serif; margin: 0; color: #1b1b1b; background: #fafafa; }
header { background: #263238; color: #fff; padding: 10px 24px; }
header h1 { margin: 0; font-size: 20px; } header p { margin: 0; opacity: .7; }
main { padding: 8px 24px 48px; max-width: 1400px; }
h2 { font-size: 17px; overflow-wrap: anywhere; border-bottom: 1px solid #ccc; margin-top: 32px; }
h3 { font-size: 15px; margin: 18px 0 6px; }
.error { color: var(--error); } .warning { color: var(--warning); } .info { color: var(--info); }
.sev { font-weight: 600; } .sev.ok { color: var(--ok); }
.verdict { font-weight: 600; } .verdict.v0 { color: var(--ok); }
.verdict.v1, .verdict.v2 { color: var(--error); }
[hidden] { display: none !important; }
dl.summary { display: grid; grid-template-columns: max-content 1fr; gap: 2px 14px; margin: 0; }
dl.summary dt { color: #555; } dl.summary dd { margin: 0; overflow-wrap: anywhere; }
ul.problems li { color: var(--error); overflow-wrap: anywhere; }
.none { color: #777; font-style: italic; }
.js .needs-js { display: none; }
tr:target { background: #fff3b0; }
details.help { margin: 10px 0; color: #444; } details.help summary { cursor: pointer; }

.index-controls { display: flex; flex-wrap: wrap; gap: 6px 16px; align-items: center;
  margin: 6px 0; }
.index-controls .count { color: #555; }
.index-wrap { overflow-x: auto; max-height: 60vh; overflow-y: auto; border: 1px solid #ddd;
  background: #fff; }
table.index { border-collapse: collapse; width: 100%; font-size: 13px; }
table.index th { position: sticky; top: 0; background: #eceff1; text-align: left;
  white-space: nowrap; }
table.index th button { font: inherit; font-weight: 600; background: none; border: 0;
  padding: 4px 6px; cursor: pointer; }
table.index th[aria-sort=ascending] button::after { content: " ▲"; }
table.index th[aria-sort=descending] button::after { content: " ▼"; }
table.index td { padding: 2px 6px; border-top: 1px solid #eee; vertical-align: top; }
table.index td:first-child { overflow-wrap: anywhere; min-width: 14em; }
table.index td:nth-child(9) { min-width: 9em; }
@media (max-width: 900px) {
  table.index th:nth-child(2), table.index td:nth-child(2),
  table.index th:nth-child(4), table.index td:nth-child(4),
  table.index th:nth-child(10), table.index td:nth-child(10) { display: none; }
  main { padding: 8px 12px 48px; }
}
table.index td:first-child { border-left: 4px solid transparent; }
table.index tr.sev-error td:first-child { border-left-color: var(--error); }
table.index tr.sev-warning td:first-child { border-left-color: var(--warning); }
table.index tr.sev-info td:first-child { border-left-color: var(--info); }
table.index tr.sev-error td:nth-child(6), table.index tr.sev-warning td:nth-child(7) {
  font-weight: 700; }

table.findings { border-collapse: collapse; width: 100%; table-layout: fixed; }
col.c-time { width: 8em; } col.c-rule { width: 5.5em; } col.c-severity { width: 5.5em; }
col.c-vehicle { width: 12%; } col.c-location { width: 22%; }
table.findings th, table.findings td { border-bottom: 1px solid #ddd; padding: 3px 6px;
  text-align: left; vertical-align: top; }
table.findings td { overflow-wrap: anywhere; }
article.rule { background: #fff; border: 1px solid #ddd; padding: 4px 14px; margin: 10px 0; }
article.rule pre { overflow-x: auto; }
article.rule:target { border-color: #f9a825; box-shadow: 0 0 0 3px #fff3b0; }

figure.timeline { margin: 8px 0 16px; background: #fff; border: 1px solid #ddd;
  padding: 6px 8px; }
figure.timeline:focus { outline: 2px solid #90caf9; }
figure.timeline figcaption { color: #444; margin-bottom: 4px; overflow-wrap: anywhere; }
.toolbar { display: flex; flex-wrap: wrap; gap: 4px; align-items: center; margin: 4px 0; }
.toolbar button { font: inherit; padding: 0 8px; border: 1px solid #bbb; background: #f5f5f5;
  border-radius: 3px; cursor: pointer; }
.toolbar .range { color: #444; margin-left: 8px; font-variant-numeric: tabular-nums; }
.plots { position: relative; }
.uplot { width: auto; }
.u-legend { font-size: 12px; text-align: left; }
.u-legend .u-series th { font-weight: normal; }
.lane { position: relative; overflow: hidden; }
.lane.marks { height: 20px; }
.mark { position: absolute; top: 0; transform: translateX(-50%); text-decoration: none;
  font: 600 10px/16px system-ui, sans-serif; color: #fff; text-align: center; }
.mark:not(.group)::before { content: ""; display: block; width: 0; height: 0;
  border-left: 6px solid transparent; border-right: 6px solid transparent;
  border-top: 12px solid var(--info); margin-top: 4px; }
.mark.warning:not(.group)::before { border-top-color: var(--warning); }
.mark.error:not(.group)::before { border-top-color: var(--error); }
.mark.group { min-width: 16px; height: 16px; padding: 0 3px; border-radius: 8px; margin-top: 2px;
  background: var(--info); }
.mark.group.warning { background: var(--warning); } .mark.group.error { background: var(--error); }
.mark:target::before { border-top-color: #000 !important; }
.mark:target, .mark:hover { z-index: 2; filter: drop-shadow(0 0 2px #f9a825); }
.lane.notes { font-size: 11px; margin-top: 4px; }
.note { position: absolute; top: 0; height: 18px; white-space: nowrap; line-height: 16px; }
.row-name { position: absolute; left: 0; text-align: right; color: #555; line-height: 16px;
  white-space: nowrap; overflow: hidden; text-overflow: ellipsis; }
.note .tick { display: inline-block; width: 2px; height: 14px; vertical-align: middle;
  background: #607d8b; margin-right: 3px; }
.note .label { color: #333; display: inline-block; overflow: hidden; text-overflow: ellipsis;
  vertical-align: middle; }
.note.error .tick { background: var(--error); } .note.warning .tick { background: var(--warning); }
.note.ok .tick { background: var(--ok); }
.note.failsafe .label { color: var(--error); font-weight: 600; }
.note.cmd .tick { background: #37474f; width: 3px; }
.readout { min-height: 1.45em; color: #333; font-size: 12px; overflow-wrap: anywhere;
  font-variant-numeric: tabular-nums; }
"""

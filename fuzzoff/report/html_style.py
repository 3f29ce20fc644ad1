"""The HTML report's inline style sheet (kept apart so html.py reads as structure)."""

CSS = """
:root { --error: #c62828; --warning: #b26a00; --info: #1565c0; --ok: #2e7d32; }
body { font: 14px/1.45 system-ui, sans-serif; margin: 0; color: #1b1b1b; background: #fafafa; }
header { background: #263238; color: #fff; padding: 10px 24px; }
header h1 { margin: 0; font-size: 20px; } header p { margin: 0; opacity: .7; }
main { padding: 8px 24px 48px; max-width: 1100px; }
h2 { font-size: 17px; word-break: break-all; border-bottom: 1px solid #ccc; margin-top: 32px; }
h3 { font-size: 15px; margin: 18px 0 6px; }
.error { color: var(--error); } .warning { color: var(--warning); } .info { color: var(--info); }
.sev { font-weight: 600; } .sev.ok { color: var(--ok); }
.verdict { font-weight: 600; } .verdict.v0 { color: var(--ok); }
.verdict.v1, .verdict.v2 { color: var(--error); }
dl.summary { display: grid; grid-template-columns: max-content 1fr; gap: 2px 14px; margin: 0; }
dl.summary dt { color: #555; } dl.summary dd { margin: 0; word-break: break-all; }
ul.problems li { color: var(--error); word-break: break-all; }
figure { margin: 8px 0 16px; } figcaption { color: #444; margin-bottom: 4px; }
table.findings { border-collapse: collapse; width: 100%; table-layout: fixed; }
col.c-time { width: 8em; } col.c-rule { width: 5.5em; } col.c-severity { width: 5.5em; }
col.c-vehicle { width: 12%; } col.c-location { width: 22%; }
table.findings th, table.findings td { border-bottom: 1px solid #ddd; padding: 3px 6px;
  text-align: left; vertical-align: top; }
table.findings td { overflow-wrap: anywhere; }
tr:target { background: #fff3b0; }
.none { color: #777; font-style: italic; }
article.rule { background: #fff; border: 1px solid #ddd; padding: 4px 14px; margin: 10px 0; }
article.rule:target { border-color: #f9a825; box-shadow: 0 0 0 3px #fff3b0; }
a.ext { text-decoration: none; }
svg.timeline { max-width: 100%; height: auto; background: #fff; border: 1px solid #ddd; }
svg text { font: 11px system-ui, sans-serif; fill: #333; }
svg .lbl, svg .tick { text-anchor: end; } svg .ttick { text-anchor: middle; }
svg .rate-l { text-anchor: end; font-weight: 600; } svg .loss-l { font-weight: 600; }
svg .panel { fill: #fcfcfc; stroke: #bbb; } svg .band-bg { fill: #f1f1f1; }
svg .grid { stroke: #e4e4e4; } svg .axis { stroke: #666; }
svg .series { fill: none; stroke: #1565c0; stroke-width: 1.2; }
svg .tail { fill: none; stroke: #1565c0; stroke-dasharray: 4 3; }
svg .rate { stroke: #b26a00; stroke-dasharray: 6 3; } svg .rate-l { fill: #b26a00; }
svg .loss { stroke: #c62828; stroke-dasharray: 2 2; } svg .loss-l { fill: #c62828; }
svg .seg { fill: #fff; font-size: 10px; pointer-events: none; }
svg .m-offboard { fill: #2e7d32; } svg .m-unknown { fill: #9e9e9e; }
svg .m-0 { fill: #5c6bc0; } svg .m-1 { fill: #8d6e63; } svg .m-2 { fill: #00838f; }
svg .m-3 { fill: #6a1b9a; } svg .m-4 { fill: #ef6c00; } svg .m-5 { fill: #455a64; }
svg .disarmed { opacity: .45; }
svg .s-ok { fill: #66bb6a; } svg .s-lost { fill: #e57373; } svg .sp { fill: #42a5f5; }
svg .mark line { stroke-width: 1.2; opacity: .8; } svg .mark .span { opacity: .10; }
svg .mark.error line { stroke: var(--error); } svg .mark.error path,
svg .mark.error .span { fill: var(--error); }
svg .mark.warning line { stroke: var(--warning); } svg .mark.warning path,
svg .mark.warning .span { fill: var(--warning); }
svg .mark.info line { stroke: var(--info); } svg .mark.info path,
svg .mark.info .span { fill: var(--info); }
svg .mark:target line, svg .mark:hover line { stroke-width: 3.5; opacity: 1; }
svg .mark:target path { stroke: #000; }
"""

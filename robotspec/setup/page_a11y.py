"""What the setup page adds to viser's client for the keyboard and screen readers.

Why a script of our own: viser's GUI API has no aria attributes and no hook for its client's
markup, and some of what a screen reader needs is in viser's widgets, not in ours (its folder
titles are divs a keyboard cannot reach, its sliders' thumbs carry no name, its icon buttons no
text). The page's HTML passes through the access check anyway (``setup/access.py``), so this
module's style and script are added to it there: the script names what viser left unnamed, from
what the page already shows (a slider is named by its row's label, a folder title by its text),
and makes folder titles focusable buttons that Enter and Space open. Nothing here changes what
the page does, only how it can be reached; axe-core in the browser test checks the result.
"""

from __future__ import annotations

__all__ = ["ADDITIONS", "add_to_page"]

#: Darker than Mantine's dimmed grey (#868e96, contrast 3.3 on white) so labels reach 4.5:1;
#: nothing scrolls sideways at 1280x800.
_STYLE = """
<style id="robotspec-a11y">
label, .mantine-InputWrapper-label, .mantine-Input-label { color: #495057 !important; }
.mantine-Notification-description { color: #495057 !important; }
html, body { overflow-x: hidden; }
[data-robotspec-folder]:focus-visible { outline: 2px solid #1971c2; outline-offset: 2px; }
#robotspec-skip { position: absolute; left: -9999px; z-index: 1000; }
#robotspec-skip:focus { left: 0.5em; top: 0.5em; background: #fff; color: #0d47a1;
  padding: 0.4em 0.8em; border: 2px solid #0d47a1; }
</style>
"""

_SCRIPT = r"""
<script id="robotspec-a11y-script">
(() => {
  const named = (el) => (el.getAttribute("aria-label") || el.textContent || "").trim() !== ""
    || el.hasAttribute("aria-labelledby") || el.hasAttribute("title");
  const ICONS = { "share": "share", "x": "close", "chevron": "collapse or expand",
    "layout": "panel layout", "eye": "show or hide", "settings": "settings" };
  function iconName(button) {
    const svg = button.querySelector("svg");
    const cls = svg ? String(svg.getAttribute("class") || "") : "";
    const m = cls.match(/tabler-icon-([a-z0-9-]+)/);
    if (button.classList.contains("mantine-Notification-closeButton")
        || button.classList.contains("mantine-CloseButton-root")) return "close";
    if (!m) return "button";
    const key = Object.keys(ICONS).find((k) => m[1].startsWith(k));
    return key ? ICONS[key] : m[1].replace(/-/g, " ");
  }
  function labelFor(el) {
    // The label viser draws beside an input: the nearest <label> before it in its row.
    let row = el;
    for (let i = 0; i < 6 && row; i++) {
      row = row.parentElement;
      const label = row && row.querySelector("label");
      if (label && label.textContent.trim()) return label;
    }
    return null;
  }
  let seq = 0;
  function fix() {
    document.querySelectorAll("button").forEach((b) => {
      if (!named(b)) b.setAttribute("aria-label", iconName(b));
    });
    document.querySelectorAll("img:not([alt])").forEach((i) => i.setAttribute("alt", ""));
    document.querySelectorAll("[role=slider]").forEach((s) => {
      if (named(s)) return;
      const label = labelFor(s);
      if (label) {
        if (!label.id) label.id = "robotspec-label-" + (++seq);
        s.setAttribute("aria-labelledby", label.id);
      } else s.setAttribute("aria-label", "value");
    });
    document.querySelectorAll("input, textarea").forEach((i) => {
      if (named(i) || (i.id && document.querySelector(`label[for="${CSS.escape(i.id)}"]`))) return;
      const label = labelFor(i);
      if (label) {
        if (!label.id) label.id = "robotspec-label-" + (++seq);
        i.setAttribute("aria-labelledby", label.id);
      }
    });
    // Folder titles: a Paper holding text and a chevron, clicked to fold: a keyboard button.
    document.querySelectorAll(".mantine-Paper-root > svg[class*=tabler-icon-chevron]")
      .forEach((svg) => {
        const title = svg.parentElement;
        if (title.hasAttribute("data-robotspec-folder")) {
          title.setAttribute("aria-expanded", String(/chevron-up/.test(svg.getAttribute("class"))));
          return;
        }
        title.setAttribute("data-robotspec-folder", "");
        title.setAttribute("role", "button");
        title.setAttribute("tabindex", "0");
        title.setAttribute("aria-expanded", String(/chevron-up/.test(svg.getAttribute("class"))));
        title.addEventListener("keydown", (e) => {
          if (e.key === "Enter" || e.key === " ") { e.preventDefault(); title.click(); }
        });
      });
    if (!document.querySelector("h1")) {  // a screen reader's first stop: what this page is
      const h1 = document.createElement("h1");
      if (document.title === "Viser") document.title = "robotspec setup";
      h1.textContent = "robotspec setup assistant";
      h1.setAttribute("style", "position:absolute;width:1px;height:1px;overflow:hidden;"
        + "clip:rect(0 0 0 0);white-space:nowrap");
      const header = document.createElement("header");  // a landmark: nothing outside one
      header.appendChild(h1);
      // The first Tab stop: past the tree's buttons (one per link) to the panel's undo.
      const skip = document.createElement("a");
      skip.href = "#";
      skip.id = "robotspec-skip";
      skip.textContent = "skip to the setup panel";
      skip.addEventListener("click", (e) => {
        e.preventDefault();
        const undo = [...document.querySelectorAll("button")]
          .find((b) => b.textContent.trim() === "undo");
        if (undo) undo.focus();
      });
      header.appendChild(skip);
      document.body.prepend(header);
    }
    if (!document.querySelector("main")) {
      const root = document.getElementById("root");
      if (root) root.setAttribute("role", "main");
    }
  }
  // Ctrl+Z / Ctrl+Shift+Z (and Ctrl+Y): the page's undo and redo buttons, except in a text
  // box, where they undo the typing as everywhere.
  addEventListener("keydown", (e) => {
    if (!(e.ctrlKey || e.metaKey) || e.altKey) return;
    const key = e.key.toLowerCase();
    if (key !== "z" && key !== "y") return;
    const t = e.target;
    const typing = t && (t.tagName === "TEXTAREA" || t.isContentEditable
      || (t.tagName === "INPUT" && !/^(button|checkbox|radio|range)$/i.test(t.type)));
    if (typing) return;
    const which = key === "y" || e.shiftKey ? "redo" : "undo";
    const button = [...document.querySelectorAll("button")]
      .find((b) => b.textContent.trim() === which);
    if (button) { e.preventDefault(); button.click(); }
  });
  let queued = false;
  const later = () => { if (!queued) { queued = true; requestAnimationFrame(() => {
    queued = false; fix(); }); } };
  addEventListener("DOMContentLoaded", () => {
    fix();
    new MutationObserver(later).observe(document.body, { childList: true, subtree: true });
  });
})();
</script>
"""

#: What is added at the start of the ``<head>`` of the page viser serves.
ADDITIONS = (_STYLE + _SCRIPT).encode()


def add_to_page(body: bytes) -> bytes:
    """The page viser serves with this module's style and script (``body`` if not a page).

    They go right after the opening ``<head>``: the first one is the page's own, whereas a
    ``</head>`` could also be text in viser's inlined script.
    """
    at = body.find(b"<head>")
    if at < 0 or b"robotspec-a11y" in body:
        return body
    at += len(b"<head>")
    return body[:at] + ADDITIONS + body[at:]

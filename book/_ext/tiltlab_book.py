"""Small fixes to the rendered pages of the book (a local Sphinx extension).

* The book has no live-code (Thebe) buttons, yet ``sphinx-thebe`` declares its
  configuration script twice on every page, which makes the browser report a
  JavaScript error. Its scripts and style sheet are dropped from every page.
* The theme expects a default colour mode; without one it logs an error on first load.
"""

from __future__ import annotations


def _drop_thebe(app, pagename, templatename, context, doctree):
    def is_thebe(asset) -> bool:
        name = str(getattr(asset, "filename", asset) or "")
        body = str(getattr(asset, "attributes", {}).get("body", ""))
        return "thebe" in name.lower() or "THEBE_JS_URL" in body

    for key in ("script_files", "css_files"):
        if key in context:
            context[key] = [a for a in context[key] if not is_thebe(a)]
    if not context.get("default_mode"):
        context["default_mode"] = "light"


def setup(app):
    app.connect("html-page-context", _drop_thebe, priority=900)
    return {"parallel_read_safe": True, "parallel_write_safe": True}

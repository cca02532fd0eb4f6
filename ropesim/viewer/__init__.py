"""`ropesim view`: a run in the browser, as one self-contained, offline HTML page with an interactive 3-D viewer.

The data flows one way, in three steps with one module each:

- ``content``: a run (a folder, or a :class:`ropesim.Trajectory`) becomes a :class:`~ropesim.viewer.content.RunContent`,
  a general description of what there is to see: lines (polylines with per-segment or per-node fields such as
  tension), points (glyphs), rigid bodies (a box with a position and an orientation quaternion), fixed shapes,
  an optional water surface and seabed, time series and the summary. :func:`~ropesim.viewer.content.run_content`
  is the one function that knows the run folder; a scene with several lines, bodies or a sea fills more entries.
- ``pack``: the contents of one or more runs become the page's data: positions quantised to a stated bound,
  delta-coded in time and along each line, compressed with zlib (the browser's DecompressionStream inflates it).
- ``page``: the data, the vendored three.js and the viewer's own script and style become one HTML file
  (:func:`~ropesim.viewer.page.write_page`), or a sandboxed iframe for a notebook.

``assets/`` holds the page's parts: ``three.min.js`` (three.js, built by ``scripts/build_three_bundle.sh``; its
licence beside it), ``viewer.js``, ``viewer.css`` and ``page.html``. ``headless`` drives a page in a headless
Chromium through Playwright, for the tests, the benchmark and the docs' screenshots.
"""


class ViewError(ValueError):
    """A page that cannot be made as asked; ``str()`` is one line naming the option or file and what is allowed."""

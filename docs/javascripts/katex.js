// Typesets the pages' equations with KaTeX (docs/vendor/katex/), after every page load, instant navigation included.
// pymdownx.arithmatex (generic) wraps each one in an element of class "arithmatex": \( ... \) inline, \[ ... \] shown
// as a block. A mistake in an equation is drawn in red (throwOnError: false) and fails tests/test_docs.py. Notebook
// pages (mkdocs-jupyter) keep their Markdown's $ ... $ as text: auto-render typesets those.
document$.subscribe(({ body }) => {
  for (const element of body.querySelectorAll(".arithmatex")) {
    const tex = element.textContent.trim();
    const display = tex.startsWith("\\[");
    katex.render(tex.slice(2, -2), element, { displayMode: display, throwOnError: false });
  }
  for (const cell of body.querySelectorAll(".jupyter-wrapper .jp-RenderedMarkdown")) {
    renderMathInElement(cell, {
      delimiters: [
        { left: "$$", right: "$$", display: true },
        { left: "$", right: "$", display: false },
      ],
      throwOnError: false,
    });
  }
});

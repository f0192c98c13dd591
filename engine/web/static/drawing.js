// A tree's drawing (Graphviz's SVG) made safe to show in a page: a drawing is data, never
// code, so scripts, foreign objects, links and event attributes are dropped. Every page
// that shows a drawing (the view, the editor) takes it from here.

export function cleanSvg(text) {
  const parsed = new DOMParser().parseFromString(text, "image/svg+xml");
  const svg = parsed.documentElement;
  for (const element of svg.querySelectorAll("script, foreignObject")) element.remove();
  for (const link of svg.querySelectorAll("a")) link.replaceWith(...link.childNodes);
  for (const element of [svg, ...svg.querySelectorAll("*")]) {
    for (const attribute of [...element.attributes]) {
      const name = attribute.name.toLowerCase();
      if (name.startsWith("on") || name.endsWith("href")) element.removeAttribute(attribute.name);
    }
  }
  return document.importNode(svg, true);
}

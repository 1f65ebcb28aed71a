// Building DOM elements; text always goes in as text, never as markup.

// h('td', {class: 'x'}, 'text', child): attributes starting with "on" become listeners.
export function h(tag, attributes = {}, ...children) {
  const element = document.createElement(tag);
  for (const [key, v] of Object.entries(attributes)) {
    if (v === undefined || v === null || v === false) continue;
    if (key.startsWith('on')) element.addEventListener(key.slice(2), v);
    else if (key === 'style') Object.assign(element.style, v);
    else element.setAttribute(key, v === true ? '' : String(v));
  }
  for (const child of children.flat()) {
    if (child === null || child === undefined || child === false) continue;
    element.append(child instanceof Node ? child : String(child));
  }
  return element;
}

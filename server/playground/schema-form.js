// A form generated from the service's own JSON Schemas (/v1/schemas/*.json). Every control
// edits one JSON pointer of the request: numbers, enums, booleans, strings and short vectors get
// inputs (colours also a colour picker); what a form cannot show well (lists of objects, oneOf)
// gets a JSON box for that subtree. Fields the request leaves out are offered as "+ name"
// buttons, so the form shows the request, not the whole schema. Problems from the server
// (problem+json `errors[].pointer`) are shown at the control of the longest matching pointer.

// The schema documents by file name, every $ref rewritten to "file#pointer".
export class Schemas {
  constructor(docs) {
    this.docs = docs;
  }

  static async load(base, names) {
    const docs = {};
    await Promise.all(names.map(async (name) => {
      const res = await fetch(`${base}${name}`);
      if (!res.ok) throw new Error(`${base}${name}: HTTP ${res.status}`);
      docs[name] = absoluteRefs(await res.json(), name);
    }));
    return new Schemas(docs);
  }

  // The schema at "file#/json/pointer".
  lookup(ref) {
    const [file, pointer = ''] = ref.split('#');
    let node = this.docs[file];
    if (!node) throw new Error(`schema ${file} not loaded`);
    for (const part of pointer.split('/').slice(1)) node = node[unescapePointer(part)];
    return node;
  }

  // Follows $ref and merges allOf, so the caller sees one plain schema.
  resolve(schema) {
    let node = schema || {}, outer = {};
    while (node.$ref) {
      const { $ref, ...rest } = node;
      outer = { ...rest, ...outer };  // the referring schema's description wins
      node = this.lookup($ref);
    }
    node = { ...node, ...outer };
    if (node.allOf) {
      let merged = { ...node };
      delete merged.allOf;
      for (const part of node.allOf) merged = mergeSchemas(merged, this.resolve(part));
      node = merged;
    }
    return node;
  }
}

function unescapePointer(s) {
  return s.replace(/~1/g, '/').replace(/~0/g, '~');
}
export function escapePointer(s) {
  return String(s).replace(/~/g, '~0').replace(/\//g, '~1');
}

function absoluteRefs(node, file) {
  if (Array.isArray(node)) return node.map((n) => absoluteRefs(n, file));
  if (!node || typeof node !== 'object') return node;
  const out = {};
  for (const [k, v] of Object.entries(node)) {
    if (k === '$ref' && typeof v === 'string') out[k] = v.startsWith('#') ? `${file}${v}` : v.includes('#') ? v : `${v}#`;
    else out[k] = absoluteRefs(v, file);
  }
  return out;
}

function mergeSchemas(a, b) {
  const out = { ...a, ...b };
  if (a.properties && b.properties) {
    out.properties = { ...a.properties };
    for (const [k, v] of Object.entries(b.properties))
      out.properties[k] = a.properties[k] ? { allOf: [a.properties[k], v] } : v;
  }
  if (a.required && b.required) out.required = [...new Set([...a.required, ...b.required])];
  return out;
}

function typesOf(s) {
  return Array.isArray(s.type) ? s.type : s.type ? [s.type] : [];
}

// How a (resolved) schema is edited.
function kindOf(schemas, s) {
  const types = typesOf(s);
  if (s.enum) return 'enum';
  // Alternatives that only say which fields are required (lightning's targets or targetRegion)
  // constrain an object's form; they do not make it another kind of field.
  const onlyRequired = (alternatives) => alternatives.every((a) => Object.keys(a).every((k) => k === 'required'));
  if ((s.oneOf && !onlyRequired(s.oneOf)) || (s.anyOf && !onlyRequired(s.anyOf)) || types.length !== 1) return 'json';
  const [t] = types;
  if (t === 'boolean') return 'boolean';
  if (t === 'number' || t === 'integer') return 'number';
  if (t === 'string') return 'string';
  if (t === 'object' && s.properties) return 'object';
  if (t === 'array' && s.maxItems && s.maxItems <= 4 && s.minItems === s.maxItems) {
    const items = schemas.resolve(s.items);
    if (['number', 'integer'].includes(typesOf(items)[0])) return 'tuple';
  }
  return 'json';
}

// A value to start a field the request left out with.
function starter(schemas, s) {
  if (s.default !== undefined) return structuredClone(s.default);
  if (s.const !== undefined) return s.const;
  switch (kindOf(schemas, s)) {
    case 'enum': return s.enum[0];
    case 'boolean': return false;
    case 'number': return s.minimum ?? (s.exclusiveMinimum !== undefined ? s.exclusiveMinimum + 1 : 0);
    case 'string': return '';
    case 'object': return {};
    case 'tuple': return new Array(s.minItems).fill(starter(schemas, schemas.resolve(s.items)));
    default: return typesOf(s)[0] === 'array' ? [] : typesOf(s)[0] === 'object' ? {} : null;
  }
}

export function getAt(root, pointer) {
  let node = root;
  for (const part of pointer.split('/').slice(1)) {
    if (node === undefined || node === null) return undefined;
    node = node[unescapePointer(part)];
  }
  return node;
}

// Sets (or, with value undefined, deletes) the member at pointer, creating objects on the way.
export function setAt(root, pointer, value) {
  const parts = pointer.split('/').slice(1).map(unescapePointer);
  const last = parts.pop();
  let node = root;
  for (const p of parts) node = node[p] ??= {};
  if (value === undefined) {
    if (Array.isArray(node)) node.splice(Number(last), 1);
    else delete node[last];
  } else node[last] = value;
}

const isColour = (s) => s.minItems === 3 && s.maxItems === 3 && s.items && s.items.maximum === 1 && s.items.minimum === 0;
// The schemas' colours are linear RGB; a colour picker speaks sRGB.
const toSrgb = (c) => (c <= 0.0031308 ? 12.92 * c : 1.055 * c ** (1 / 2.4) - 0.055);
const toLinear = (c) => (c <= 0.04045 ? c / 12.92 : ((c + 0.055) / 1.055) ** 2.4);
const toHex = (rgb) => '#' + rgb.slice(0, 3).map((c) => Math.round(toSrgb(Math.min(1, Math.max(0, +c || 0))) * 255)
  .toString(16).padStart(2, '0')).join('');
const fromHex = (h) => [1, 3, 5].map((i) => +toLinear(parseInt(h.slice(i, i + 2), 16) / 255).toFixed(4));

export class SchemaForm {
  // onEdit(): a value changed (no re-render needed); onShape(): a field was added or removed.
  constructor(root, schemas, { onEdit, onShape }) {
    Object.assign(this, { root, schemas, onEdit, onShape });
  }

  render(schemaRef, value) {
    this.value = value;
    this.schema = this.schemas.resolve({ $ref: schemaRef });
    this.root.replaceChildren(...this.members(this.schema, value, ''));
  }

  el(tag, attrs = {}, ...children) {
    const e = document.createElement(tag);
    for (const [k, v] of Object.entries(attrs)) {
      if (k.startsWith('on')) e.addEventListener(k.slice(2), v);
      else if (v !== undefined && v !== null && v !== false) e.setAttribute(k, v === true ? '' : v);
    }
    e.append(...children.filter((c) => c !== null && c !== undefined));
    return e;
  }

  // The present members of an object as fields, then "+ name" for the absent ones.
  members(schema, value, pointer) {
    const props = schema.properties || {};
    const out = [];
    const absent = [];
    for (const [name, sub] of Object.entries(props)) {
      if (value && value[name] !== undefined) out.push(this.field(name, this.schemas.resolve(sub), `${pointer}/${escapePointer(name)}`, schema));
      else absent.push(name);
    }
    if (absent.length) {
      out.push(this.el('div', { class: 'add' }, ...absent.map((name) => this.el('button', {
        type: 'button', 'data-add': `${pointer}/${escapePointer(name)}`,
        title: this.schemas.resolve(props[name]).description || '',
        onclick: () => {
          setAt(this.value, `${pointer}/${escapePointer(name)}`, starter(this.schemas, this.schemas.resolve(props[name])));
          this.onShape();
        },
      }, `+ ${name}`))));
    }
    return out;
  }

  removeButton(pointer, required) {
    if (required) return null;
    return this.el('button', { type: 'button', class: 'remove', title: 'leave this field out', onclick: () => {
      setAt(this.value, pointer, undefined);
      this.onShape();
    } }, '×');
  }

  set(pointer, v) {
    setAt(this.value, pointer, v);
    this.onEdit();
  }

  field(name, s, pointer, parent) {
    const required = (parent.required || []).includes(name);
    const value = getAt(this.value, pointer);
    const title = s.description || '';
    const kind = kindOf(this.schemas, s);
    if (kind === 'object') {
      return this.el('fieldset', { 'data-pointer': pointer },
        this.el('legend', { title }, name, ' ', this.removeButton(pointer, required)),
        ...this.members(s, value, pointer));
    }
    const label = this.el('label', { title, for: `f${pointer}` }, name);
    return this.el('div', { class: 'field', 'data-pointer': pointer }, label, this.control(kind, s, value, pointer),
      this.removeButton(pointer, required) || this.el('span'));
  }

  number(s, value, pointer, id) {
    const integer = typesOf(s).includes('integer');
    return this.el('input', {
      type: 'number', id, value, step: integer ? 1 : 'any', min: s.minimum, max: s.maximum, 'data-pointer': pointer,
      oninput: (e) => {
        const t = e.target.value;
        if (t !== '' && Number.isFinite(Number(t))) this.set(pointer, Number(t));
      },
    });
  }

  control(kind, s, value, pointer) {
    const id = `f${pointer}`;
    switch (kind) {
      case 'enum': {
        const select = this.el('select', { id, 'data-pointer': pointer,
          onchange: (e) => this.set(pointer, s.enum[e.target.selectedIndex]) },
          ...s.enum.map((v) => this.el('option', { selected: v === value }, String(v))));
        return select;
      }
      case 'boolean':
        return this.el('input', { type: 'checkbox', id, checked: !!value, 'data-pointer': pointer,
          onchange: (e) => this.set(pointer, e.target.checked) });
      case 'number': return this.number(s, value, pointer, id);
      case 'string':
        return this.el('input', { type: 'text', id, value, 'data-pointer': pointer,
          oninput: (e) => this.set(pointer, e.target.value) });
      case 'tuple': {
        const items = this.schemas.resolve(s.items);
        const inputs = Array.from({ length: s.maxItems }, (_, i) => this.number(items, Array.isArray(value) ? value[i] : '',
          `${pointer}/${i}`, i === 0 ? id : undefined));
        if (isColour(s) && Array.isArray(value)) {
          inputs.push(this.el('input', { type: 'color', value: toHex(value), title: 'pick a colour', oninput: (e) => {
            this.set(pointer, fromHex(e.target.value));
            fromHex(e.target.value).forEach((c, i) => { inputs[i].value = c; });
          } }));
        }
        return this.el('div', { class: 'tuple' }, ...inputs);
      }
      default: {
        const area = this.el('textarea', { id, rows: Math.min(8, JSON.stringify(value).length / 40 + 1),
          'data-pointer': pointer, title: 'JSON',
          oninput: (e) => {
            try {
              this.set(pointer, JSON.parse(e.target.value));
              e.target.setCustomValidity('');
            } catch (err) {
              e.target.setCustomValidity(err.message);
            }
          } });
        area.value = JSON.stringify(value);
        return area;
      }
    }
  }

  // Marks the controls named by problem pointers; returns the problems no control took.
  showErrors(errors) {
    for (const e of this.root.querySelectorAll('.field-error')) e.remove();
    for (const e of this.root.querySelectorAll('.invalid')) e.classList.remove('invalid');
    const homeless = [];
    for (const err of errors) {
      let pointer = err.pointer || '', target = null;
      while (!target) {
        target = [...this.root.querySelectorAll('.field[data-pointer], fieldset[data-pointer]')]
          .find((n) => n.dataset.pointer === pointer);
        if (target || pointer === '') break;
        pointer = pointer.slice(0, pointer.lastIndexOf('/'));
      }
      if (!target) {
        homeless.push(err);
        continue;
      }
      target.classList.add('invalid');
      const msg = this.el('p', { class: 'field-error', 'data-error-for': err.pointer }, `${err.pointer || '/'}: ${err.message}`);
      if (target.tagName === 'FIELDSET') target.querySelector('legend').after(msg);
      else target.append(msg);
    }
    return homeless;
  }
}

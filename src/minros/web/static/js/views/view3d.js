// 3D: Rviz in the page (the view itself is ../view3d/view.js). three.js is 2 MB of modules, so
// they load when the view is first shown, not with the page; until then the view is this stub,
// which then takes on the real view's methods and properties (tests read them through it).

import {h} from "../ui.js";

export function createView3dView(app) {
  const el = h("section", {}, h("p", {class: "muted"}, "Loading the 3D view…"));
  let loading = null;
  const view = {
    id: "3d", el, ready: false,
    show() {
      load().then((real) => real && real.show());
    },
    hide() {},
    open(args) {
      load().then((real) => real && real.open(args));
    },
  };

  function load() {
    if (!loading) {
      loading = import("../view3d/view.js").then(({createView}) => {
        const real = createView(app, el);
        Object.defineProperties(view, Object.getOwnPropertyDescriptors(real));
        view.ready = true;
        return real;
      }).catch((err) => {
        el.replaceChildren(h("div", {class: "error-line visible"},
          `The 3D view could not load: ${err.message}. It needs a browser with WebGL 2.`));
        console.warn(err);
        return null;
      });
    }
    return loading;
  }
  return view;
}

// The replay page's scene: three.js objects for a parsed recording (recording.js) and the per-frame update.
// Scree's z is up (camera.up = +z). Bodies are groups of meshes posed from the frame's f64 poses; particles
// are one InstancedMesh (a low-poly sphere per particle, scaled by its radius, coloured by speed or by
// material); height fields are shaded BufferGeometry grids updated by the frames' changed rectangles;
// contacts are a Points overlay drawn over everything.
"use strict";

const ScreeScene = (() => {
  const srgb = (rgb) => new THREE.Color().setRGB(rgb[0] / 255, rgb[1] / 255, rgb[2] / 255, THREE.SRGBColorSpace);
  const DEFAULT_RGB = [170, 170, 170];

  // Speed colour map: dark blue (at rest) -> cyan -> yellow -> red (fastest), as sRGB stops.
  const RAMP = [[40, 60, 150], [40, 170, 220], [240, 220, 60], [220, 40, 30]];
  function rampRgb(s) {
    s = Math.min(1, Math.max(0, s)) * (RAMP.length - 1);
    const i = Math.min(RAMP.length - 2, Math.floor(s)), u = s - i;
    return RAMP[i].map((a, k) => a + (RAMP[i + 1][k] - a) * u);
  }
  // 256-entry linear-RGB table of the ramp, so a frame's colours are a lookup per particle.
  const RAMP_LINEAR = (() => {
    const t = new Float32Array(256 * 3), c = new THREE.Color();
    for (let i = 0; i < 256; ++i) {
      c.copy(srgb(rampRgb(i / 255)));
      t[3 * i] = c.r; t[3 * i + 1] = c.g; t[3 * i + 2] = c.b;
    }
    return t;
  })();

  function heightFieldGeometry(hf) {
    const { nx, ny, elementSize: e } = hf;
    const g = new THREE.BufferGeometry();
    const pos = new Float32Array(3 * nx * ny);
    for (let j = 0; j < ny; ++j)
      for (let i = 0; i < nx; ++i) {
        const v = j * nx + i;
        pos[3 * v] = i * e; pos[3 * v + 1] = j * e; pos[3 * v + 2] = hf.heights[v];
      }
    // Two triangles per cell split along the diagonal (i, j)-(i+1, j+1), counter-clockwise seen from +z.
    const idx = new Uint32Array(6 * (nx - 1) * (ny - 1));
    let k = 0;
    for (let j = 0; j + 1 < ny; ++j)
      for (let i = 0; i + 1 < nx; ++i) {
        const a = j * nx + i, b = a + 1, c = a + nx + 1, d = a + nx;
        idx.set([a, b, c, a, c, d], k);
        k += 6;
      }
    g.setAttribute("position", new THREE.BufferAttribute(pos, 3));
    g.setIndex(new THREE.BufferAttribute(idx, 1));
    g.computeVertexNormals();
    return g;
  }

  class Scene {
    constructor(rec, container) {
      this.rec = rec;
      const renderer = (this.renderer = new THREE.WebGLRenderer({ antialias: true }));
      renderer.setPixelRatio(window.devicePixelRatio || 1);
      renderer.setSize(container.clientWidth, container.clientHeight);
      container.appendChild(renderer.domElement);
      const scene = (this.scene = new THREE.Scene());
      scene.background = new THREE.Color(0x1e2228);
      const camera = (this.camera = new THREE.PerspectiveCamera(40, container.clientWidth / container.clientHeight, 0.01, 1000));
      camera.up.set(0, 0, 1);
      scene.add(new THREE.HemisphereLight(0xdfe8ff, 0x4a4038, 1.2));
      const sun = new THREE.DirectionalLight(0xffffff, 1.8);
      sun.position.set(3, -5, 8);
      scene.add(sun);

      this.materials = rec.scene.materials.map((m) => new THREE.MeshLambertMaterial({ color: srgb(m.rgb) }));
      this.defaultMaterial = new THREE.MeshLambertMaterial({ color: srgb(DEFAULT_RGB) });
      this.bodies = rec.scene.bodies.map((b) => this.buildBody(b));
      this.terrains = rec.heightFields.map((hf, t) => this.buildTerrain(hf, t));
      this.buildParticles();
      this.buildContacts();
      this.shownFrame = -1;
      this.terrainFrame = 0;
      this.colourBy = "speed";
    }

    material(index) {
      return index < this.materials.length ? this.materials[index] : this.defaultMaterial;
    }

    buildBody(b) {
      const group = new THREE.Group();
      group.name = b.name;
      for (const g of b.geometries) {
        let obj = null;
        const mat = this.material(g.material);
        switch (g.shape) {
          case "sphere": obj = new THREE.Mesh(new THREE.SphereGeometry(g.radius, 24, 16), mat); break;
          case "box": {
            const [x, y, z] = g.halfExtents;
            obj = new THREE.Mesh(new THREE.BoxGeometry(2 * x, 2 * y, 2 * z), mat);
            break;
          }
          case "capsule": obj = new THREE.Mesh(new THREE.CapsuleGeometry(g.radius, g.height, 8, 16).rotateX(Math.PI / 2), mat); break;
          case "cylinder": obj = new THREE.Mesh(new THREE.CylinderGeometry(g.radius, g.radius, g.height, 24).rotateX(Math.PI / 2), mat); break;
          case "plane": {
            // Points x with normal . x = offset, drawn as a 40 m square, a little transparent.
            const n = new THREE.Vector3(...g.normal).normalize();
            const pm = mat.clone();
            pm.transparent = true; pm.opacity = 0.5; pm.side = THREE.DoubleSide; pm.depthWrite = false;
            obj = new THREE.Mesh(new THREE.PlaneGeometry(40, 40), pm);
            obj.quaternion.setFromUnitVectors(new THREE.Vector3(0, 0, 1), n);
            obj.position.copy(n.multiplyScalar(g.offset));
            obj.userData.unbounded = true;
            const holder = new THREE.Group();
            holder.add(obj);
            obj = holder;
            obj.userData.unbounded = true;
            break;
          }
          case "convex": {
            let geo = new THREE.BufferGeometry();
            geo.setAttribute("position", new THREE.BufferAttribute(g.vertices, 3));
            geo.setIndex(new THREE.BufferAttribute(g.triangles, 1));
            geo = geo.toNonIndexed();  // flat shading: one normal per face
            geo.computeVertexNormals();
            obj = new THREE.Mesh(geo, mat);
            break;
          }
          case "line": {
            const geo = new THREE.BufferGeometry().setFromPoints([new THREE.Vector3(...g.a), new THREE.Vector3(...g.b)]);
            obj = new THREE.Line(geo, new THREE.LineBasicMaterial({ color: mat.color }));
            break;
          }
          case "heightfield":
            // Drawn by the terrain at its HFLD pose (docs/recording.md), not here.
            if (g.terrain < this.rec.heightFields.length && g.material < this.materials.length)
              this.rec.heightFields[g.terrain].material = g.material;
            break;
        }
        if (!obj) continue;
        if (g.shape !== "plane") {
          obj.position.set(...g.position);
          obj.quaternion.set(...g.rotation);
        }
        group.add(obj);
      }
      this.scene.add(group);
      return group;
    }

    buildTerrain(hf) {
      const geo = heightFieldGeometry(hf);
      const base = hf.material !== undefined ? this.materials[hf.material] : null;
      const mat = new THREE.MeshLambertMaterial({ color: base ? base.color : srgb([196, 170, 120]), side: THREE.DoubleSide });
      const mesh = new THREE.Mesh(geo, mat);
      mesh.position.set(...hf.position);
      mesh.quaternion.set(...hf.rotation);
      this.scene.add(mesh);
      return { hf, mesh, geo };
    }

    buildParticles() {
      const cap = Math.max(1, this.rec.maxParticles);
      // 20 triangles per particle when there are many (the page must play 10,000 at 30 frames/s), 80 otherwise.
      const sphere = new THREE.IcosahedronGeometry(1, cap > 3000 ? 0 : 1);
      const mat = new THREE.MeshLambertMaterial({ color: 0xffffff });
      const mesh = (this.particles = new THREE.InstancedMesh(sphere, mat, cap));
      mesh.instanceMatrix.setUsage(THREE.DynamicDrawUsage);
      mesh.instanceColor = new THREE.InstancedBufferAttribute(new Float32Array(3 * cap), 3);
      mesh.instanceColor.setUsage(THREE.DynamicDrawUsage);
      mesh.count = 0;
      mesh.frustumCulled = false;
      this.particleMaterialColours = this.rec.scene.particleMaterials.map((m) => srgb(m.rgb));
      this.scene.add(mesh);
    }

    buildContacts() {
      const cap = Math.max(1, this.rec.maxContacts);
      const geo = new THREE.BufferGeometry();
      geo.setAttribute("position", new THREE.BufferAttribute(new Float32Array(3 * cap), 3).setUsage(THREE.DynamicDrawUsage));
      geo.setDrawRange(0, 0);
      const mat = new THREE.PointsMaterial({ color: 0xff3050, size: 5, sizeAttenuation: false, depthTest: false, transparent: true });
      this.contacts = new THREE.Points(geo, mat);
      this.contacts.renderOrder = 10;
      this.contacts.frustumCulled = false;
      this.scene.add(this.contacts);
    }

    // Heights of every terrain as of frame k: forward from the shown state, or from the initial heights.
    setTerrainFrame(k) {
      if (!this.terrains.length) return;
      let from = this.terrainFrame;
      if (k < from) {
        for (const t of this.terrains) {
          const pos = t.geo.attributes.position.array, h0 = t.hf.heights;
          for (let v = 0; v < h0.length; ++v) pos[3 * v + 2] = h0[v];
        }
        from = 0;
      }
      const changed = new Set();
      for (let f = from + 1; f <= k; ++f) {
        const rectsPerTerrain = this.rec.frames[f].terrainRects;
        rectsPerTerrain.forEach((rects, t) => {
          const { hf, geo } = this.terrains[t];
          const pos = geo.attributes.position.array;
          for (const r of rects) {
            for (let j = 0; j < r.h; ++j)
              for (let i = 0; i < r.w; ++i) pos[3 * ((r.j0 + j) * hf.nx + r.i0 + i) + 2] = r.heights[j * r.w + i];
            changed.add(t);
          }
        });
      }
      if (k < this.terrainFrame) this.terrains.forEach((_, t) => changed.add(t));
      for (const t of changed) {
        const geo = this.terrains[t].geo;
        geo.attributes.position.needsUpdate = true;
        geo.computeVertexNormals();
        geo.computeBoundingSphere();
      }
      this.terrainFrame = k;
    }

    showFrame(k, contactsOn) {
      const f = this.rec.frames[k];
      const p = f.poses;
      this.bodies.forEach((g, b) => {
        g.position.set(p[7 * b], p[7 * b + 1], p[7 * b + 2]);
        g.quaternion.set(p[7 * b + 3], p[7 * b + 4], p[7 * b + 5], p[7 * b + 6]);
      });
      // Particles: the instance matrix is a uniform scale by the radius and a translation, written directly.
      const n = f.count, m = this.particles.instanceMatrix.array, col = this.particles.instanceColor.array;
      const x = f.positions, rad = f.radii;
      for (let i = 0; i < n; ++i) {
        const r = rad[i], o = 16 * i;
        m[o] = r; m[o + 1] = 0; m[o + 2] = 0; m[o + 3] = 0;
        m[o + 4] = 0; m[o + 5] = r; m[o + 6] = 0; m[o + 7] = 0;
        m[o + 8] = 0; m[o + 9] = 0; m[o + 10] = r; m[o + 11] = 0;
        m[o + 12] = x[3 * i]; m[o + 13] = x[3 * i + 1]; m[o + 14] = x[3 * i + 2]; m[o + 15] = 1;
      }
      if (this.colourBy === "speed") {
        const scale = this.rec.maxSpeed > 0 ? 255 / this.rec.maxSpeed : 0, s = f.speeds;
        for (let i = 0; i < n; ++i) {
          const q = 3 * Math.min(255, Math.round(s[i] * scale));
          col[3 * i] = RAMP_LINEAR[q]; col[3 * i + 1] = RAMP_LINEAR[q + 1]; col[3 * i + 2] = RAMP_LINEAR[q + 2];
        }
      } else {
        const mats = f.materials, pc = this.particleMaterialColours, dflt = srgb(DEFAULT_RGB);
        for (let i = 0; i < n; ++i) {
          const c = pc[mats[i]] || dflt;
          col[3 * i] = c.r; col[3 * i + 1] = c.g; col[3 * i + 2] = c.b;
        }
      }
      this.particles.count = n;
      this.particles.instanceMatrix.needsUpdate = true;
      this.particles.instanceColor.needsUpdate = true;
      // Contacts: points only (the normal force is in the file for tools that want it).
      const c = f.contacts, nc = c.length / 7, cp = this.contacts.geometry.attributes.position;
      for (let i = 0; i < nc; ++i) {
        cp.array[3 * i] = c[7 * i]; cp.array[3 * i + 1] = c[7 * i + 1]; cp.array[3 * i + 2] = c[7 * i + 2];
      }
      cp.needsUpdate = true;
      this.contacts.geometry.setDrawRange(0, nc);
      this.contacts.visible = contactsOn;
      this.setTerrainFrame(k);
      this.shownFrame = k;
    }

    // Bounding box of what frame k shows (planes left out: they are unbounded).
    bounds(k) {
      const box = new THREE.Box3();
      this.scene.updateMatrixWorld(true);
      for (const g of this.bodies)
        g.traverse((o) => {
          if (o.userData.unbounded) return;
          if (o.isMesh || o.isLine) box.expandByObject(o);
        });
      for (const t of this.terrains) box.expandByObject(t.mesh);
      const f = this.rec.frames[k], v = new THREE.Vector3();
      for (let i = 0; i < f.count; ++i) box.expandByPoint(v.set(f.positions[3 * i], f.positions[3 * i + 1], f.positions[3 * i + 2]));
      if (box.isEmpty()) box.set(new THREE.Vector3(-1, -1, -1), new THREE.Vector3(1, 1, 1));
      return box;
    }

    resize(w, h) {
      this.camera.aspect = w / h;
      this.camera.updateProjectionMatrix();
      this.renderer.setSize(w, h);
    }

    render() { this.renderer.render(this.scene, this.camera); }

    // CSS-pixel position in the canvas of a world point, as the camera shows it now.
    project(x, y, z) {
      const v = new THREE.Vector3(x, y, z).project(this.camera);
      const el = this.renderer.domElement.getBoundingClientRect();
      return { x: el.left + (v.x + 1) / 2 * el.width, y: el.top + (1 - v.y) / 2 * el.height, depth: v.z };
    }
  }

  return { Scene, rampRgb };
})();

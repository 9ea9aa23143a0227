// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
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

  // A unit icosphere with shared vertices (three's IcosahedronGeometry repeats them per face: 60 vertices for
  // 20 faces), so each particle costs 12 vertex-shader runs at detail 0 (42 at detail 1), and the normals are
  // the sphere's (smooth shading).
  function indexedSphere(detail) {
    const src = new THREE.IcosahedronGeometry(1, detail).attributes.position.array;
    const key = new Map(), pos = [], idx = [];
    for (let v = 0; v < src.length / 3; ++v) {
      const x = src[3 * v], y = src[3 * v + 1], z = src[3 * v + 2];
      const k = `${Math.round(x * 1e4)},${Math.round(y * 1e4)},${Math.round(z * 1e4)}`;
      if (!key.has(k)) { key.set(k, pos.length / 3); pos.push(x, y, z); }
      idx.push(key.get(k));
    }
    const g = new THREE.BufferGeometry();
    g.setAttribute("position", new THREE.Float32BufferAttribute(pos, 3));
    g.setAttribute("normal", new THREE.Float32BufferAttribute(pos, 3));
    g.setIndex(idx);
    return g;
  }

  class Scene {
    constructor(rec, container) {
      this.rec = rec;
      // Multisampling costs little on a GPU but much in software GL; ?aa=0 / ?aa=1 in the page's URL overrides
      // the default (on below 3000 particles).
      const aa = new URLSearchParams(window.location.search).get("aa");
      const antialias = aa !== null ? aa === "1" : rec.maxParticles < 3000;
      const renderer = (this.renderer = new THREE.WebGLRenderer({ antialias }));
      renderer.setPixelRatio(window.devicePixelRatio || 1);
      renderer.setSize(container.clientWidth, container.clientHeight);
      container.appendChild(renderer.domElement);
      const gl = renderer.getContext();
      const info = gl.getExtension("WEBGL_debug_renderer_info");
      this.glRenderer = String(gl.getParameter(info ? info.UNMASKED_RENDERER_WEBGL : gl.RENDERER));
      this.softwareGL = /swiftshader|llvmpipe|softpipe|software/i.test(this.glRenderer);
      const scene = (this.scene = new THREE.Scene());
      scene.background = new THREE.Color(0x1e2228);
      const camera = (this.camera = new THREE.PerspectiveCamera(40, container.clientWidth / container.clientHeight, 0.01, 1000));
      camera.up.set(0, 0, 1);
      // three's lights are physical (a Lambert surface returns albedo * irradiance / pi): a sky light and a
      // sun from behind the default camera's shoulder, so the top, front and side faces of a box differ.
      scene.add(new THREE.HemisphereLight(0xdfe8ff, 0x6a6058, 2.0));
      const sun = new THREE.DirectionalLight(0xffffff, 2.5);
      sun.position.set(2, -5, 6);
      scene.add(sun);

      this.materials = rec.scene.materials.map((m) => new THREE.MeshLambertMaterial({ color: srgb(m.rgb) }));
      this.defaultMaterial = new THREE.MeshLambertMaterial({ color: srgb(DEFAULT_RGB) });
      // Static geometry (grounds, walls) in a neutral grey whatever its material: scenes often give every body
      // the same material, and moving bodies in their material's colour must stand out against the ground.
      this.staticMaterial = new THREE.MeshLambertMaterial({ color: srgb([150, 150, 150]) });
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
        const mat = b.motion === 0 ? this.staticMaterial : this.material(g.material);
        switch (g.shape) {
          case "sphere": obj = new THREE.Mesh(new THREE.SphereGeometry(g.radius, 24, 16), mat); break;
          case "box": {
            const [x, y, z] = g.halfExtents;
            obj = new THREE.Mesh(new THREE.BoxGeometry(2 * x, 2 * y, 2 * z), mat);
            break;
          }
          case "capsule": obj = new THREE.Mesh(new THREE.CapsuleGeometry(g.radius, g.height, 8, 16), mat); break;
          case "cylinder": obj = new THREE.Mesh(new THREE.CylinderGeometry(g.radius, g.radius, g.height, 24), mat); break;
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
        if (g.shape === "box" || g.shape === "convex") {
          // Dark edges, so stacked boxes of one material read as separate boxes.
          const edgeColour = mat.color.clone().multiplyScalar(0.35);
          obj.add(new THREE.LineSegments(new THREE.EdgesGeometry(obj.geometry), new THREE.LineBasicMaterial({ color: edgeColour })));
        }
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

    // Two ways to draw particles, the same colours and sizes:
    //  "mesh"   one InstancedMesh of icospheres (per-instance matrix = radius scale + translation, per-instance
    //           colour): the default, cheap on any GPU;
    //  "points" sphere sprites (one vertex per particle, a shaded disc of the particle's projected radius):
    //           the default under software GL with more than 2000 particles, where instanced draws cost about
    //           25 us per instance (SwiftShader, measured: 10,000 instances = 250 ms a frame) and sprites
    //           cost one vertex each. ?particles=mesh or ?particles=points in the page's URL overrides.
    buildParticles() {
      const cap = Math.max(1, this.rec.maxParticles);
      this.particleMaterialColours = this.rec.scene.particleMaterials.map((m) => srgb(m.rgb));
      const asked = new URLSearchParams(window.location.search).get("particles");
      this.particleMode = asked === "mesh" || asked === "points" ? asked : this.softwareGL && cap > 2000 ? "points" : "mesh";
      this.particleColours = new Float32Array(3 * cap);
      if (this.particleMode === "points") {
        const g = new THREE.BufferGeometry();
        this.pointPositions = new THREE.BufferAttribute(new Float32Array(3 * cap), 3).setUsage(THREE.DynamicDrawUsage);
        this.pointRadii = new THREE.BufferAttribute(new Float32Array(cap), 1).setUsage(THREE.DynamicDrawUsage);
        this.pointColours = new THREE.BufferAttribute(this.particleColours, 3).setUsage(THREE.DynamicDrawUsage);
        g.setAttribute("position", this.pointPositions);
        g.setAttribute("radius", this.pointRadii);
        g.setAttribute("colour", this.pointColours);
        g.setDrawRange(0, 0);
        const mat = new THREE.ShaderMaterial({
          uniforms: { viewportHeight: { value: 600 } },
          vertexShader: `
            attribute float radius;
            attribute vec3 colour;
            uniform float viewportHeight;
            varying vec3 vColour;
            void main() {
              vec4 mv = modelViewMatrix * vec4(position, 1.0);
              gl_Position = projectionMatrix * mv;
              // Diameter in pixels of a sphere of this radius at this depth (perspective camera).
              gl_PointSize = max(1.0, 2.0 * radius * projectionMatrix[1][1] * 0.5 * viewportHeight / -mv.z);
              vColour = colour;
            }`,
          fragmentShader: `
            varying vec3 vColour;
            void main() {
              vec2 d = 2.0 * gl_PointCoord - 1.0;
              float r2 = dot(d, d);
              if (r2 > 1.0) discard;
              // The sphere's normal in view space (y of gl_PointCoord points down); light from the upper left
              // front and a sky term, close to the meshes' Lambert shading.
              vec3 n = vec3(d.x, -d.y, sqrt(1.0 - r2));
              float sun = max(dot(n, normalize(vec3(-0.3, 0.6, 0.75))), 0.0);
              gl_FragColor = vec4(vColour * (0.35 + 0.75 * sun), 1.0);
              #include <colorspace_fragment>
            }`,
        });
        this.particles = new THREE.Points(g, mat);
      } else {
        // 20 triangles per particle when there are many, 80 otherwise.
        const mesh = (this.particles = new THREE.InstancedMesh(indexedSphere(cap > 3000 ? 0 : 1), new THREE.MeshLambertMaterial({ color: 0xffffff }), cap));
        mesh.instanceMatrix.setUsage(THREE.DynamicDrawUsage);
        mesh.instanceColor = new THREE.InstancedBufferAttribute(this.particleColours, 3);
        mesh.instanceColor.setUsage(THREE.DynamicDrawUsage);
        mesh.count = 0;
      }
      this.particles.frustumCulled = false;
      this.scene.add(this.particles);
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
      const n = f.count, x = f.positions, rad = f.radii, col = this.particleColours;
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
      if (this.particleMode === "points") {
        this.pointPositions.array.set(x.subarray(0, 3 * n));
        this.pointRadii.array.set(rad.subarray(0, n));
        this.pointPositions.needsUpdate = this.pointRadii.needsUpdate = this.pointColours.needsUpdate = true;
        this.particles.geometry.setDrawRange(0, n);
      } else {
        // The instance matrix is a uniform scale by the radius and a translation, written directly.
        const m = this.particles.instanceMatrix.array;
        for (let i = 0; i < n; ++i) {
          const r = rad[i], o = 16 * i;
          m[o] = r; m[o + 1] = 0; m[o + 2] = 0; m[o + 3] = 0;
          m[o + 4] = 0; m[o + 5] = r; m[o + 6] = 0; m[o + 7] = 0;
          m[o + 8] = 0; m[o + 9] = 0; m[o + 10] = r; m[o + 11] = 0;
          m[o + 12] = x[3 * i]; m[o + 13] = x[3 * i + 1]; m[o + 14] = x[3 * i + 2]; m[o + 15] = 1;
        }
        this.particles.count = n;
        this.particles.instanceMatrix.needsUpdate = true;
        this.particles.instanceColor.needsUpdate = true;
      }
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

    // What the camera frames at first: the moving bodies and the particles of the first and the last frame,
    // and the height fields; static bodies only when nothing else is there (a large ground would otherwise
    // shrink a pile or a tower to a few pixels).
    viewBounds() {
      const box = new THREE.Box3(), v = new THREE.Vector3();
      const last = this.rec.frames.length - 1;
      for (const k of [last, 0]) {
        this.showFrame(k, false);
        this.scene.updateMatrixWorld(true);
        this.rec.scene.bodies.forEach((b, i) => {
          if (b.motion === 0) return;
          this.bodies[i].traverse((o) => {
            if (!o.userData.unbounded && (o.isMesh || o.isLine)) box.expandByObject(o);
          });
        });
        const f = this.rec.frames[k];
        for (let i = 0; i < f.count; ++i) box.expandByPoint(v.set(f.positions[3 * i], f.positions[3 * i + 1], f.positions[3 * i + 2]));
      }
      for (const t of this.terrains) box.expandByObject(t.mesh);
      return box.isEmpty() ? this.bounds(0) : box;
    }

    resize(w, h) {
      this.camera.aspect = w / h;
      this.camera.updateProjectionMatrix();
      this.renderer.setSize(w, h);
    }

    render() {
      if (this.particleMode === "points")
        this.particles.material.uniforms.viewportHeight.value = this.renderer.getDrawingBufferSize(new THREE.Vector2()).y;
      this.renderer.render(this.scene, this.camera);
    }

    // CSS-pixel position in the canvas of a world point, as the camera shows it now.
    project(x, y, z) {
      const v = new THREE.Vector3(x, y, z).project(this.camera);
      const el = this.renderer.domElement.getBoundingClientRect();
      return { x: el.left + (v.x + 1) / 2 * el.width, y: el.top + (1 - v.y) / 2 * el.height, depth: v.z };
    }
  }

  return { Scene, rampRgb };
})();

// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Terrain (AGX manual 25.1, agxModel::Terrain): a deformable height field. This part builds the terrain itself:
// the material map, compression hardening under what rests on or rolls over it, locked borders, and the soil
// volume ledger. Digging into particles and the dynamic height field with avalanches build on it.
//
// Construction (manual 25.1.1). Terrain(heightField) makes a static geometry for the field;
// Terrain(geometry) takes a geometry whose shape is a HeightField. In Scree a geometry holds exactly one shape,
// so "one height-field shape" is a type check; "no shape transform relative to the geometry" means: a geometry
// on a body must sit at the body origin (identity local transform) - the body carries the placement; a static
// geometry's placement is its world transform and may be anything whose +z opposes gravity. Unequal x and y
// spacing is accepted with the height field's logged warning. Wrong geometry or a non-identity local transform
// on a body throws std::invalid_argument. `sim.add(terrain)` installs the geometry (static case; a body's
// geometry comes with the body), a contact listener and a post-step listener; it throws std::invalid_argument
// and leaves the simulation unchanged when the field's +z is not against gravity (within 1e-6 in the cosine;
// zero gravity accepts any orientation).
//
// ---------------------------------------------------------------------------------------------------------------
// The compression law (manual 25.1.2.1-25.1.2.5)
// ---------------------------------------------------------------------------------------------------------------
// Per vertex: compression level c >= 0 and Young's modulus multiplier
//     m(c) = 2^((d+1) c)  capped at M                       (the manual's  1/2 * 2^((d+1) c + 1))
// d = the vertex material's deformability, M = the max compression multiplier (a power of two), so the cap is
// reached at c_max(d) = log2(M) / (d+1). The manual's prose says the ground cannot harden when d = 0, while its
// formula would still give 2^c: we follow the prose, d = 0 is non-deformable ground (m = 1, never yields, heights
// untouched by contacts). M = 1 likewise cannot harden and is treated as non-deformable.
//
// Depth and compression. Lowering a vertex by dz (pressed by a contact; later dug or pushed) raises c by
//     dc = dz * log2(M) / D          (D = the depth for max compression)
// capped at c_max(d); raising a vertex lowers c by the same rule (fresh loose soil on top; not below 0; no
// operation of this part raises vertices - merging and avalanches do, below). From
// loose soil a vertex lowered by z has m = 2^((d+1) log2(M) z / D) = M^((d+1) z / D): it reaches M at depth
// D / (d+1) <= D, so at D and deeper every material is as hard as M allows (manual 25.1.2.3), and a larger d
// hardens exponentially faster (25.1.2.1).
//   Why not dc = dz * c_max(d) / D (the reading first proposed): then m = 2^((d+1) c_max(d) z / D) = M^(z/D) for
//   every d - deformability would cancel out of the law and a plate would sink as far in any material, against
//   the manual ("harder exponentially faster with increased deformability") and against sinkage falling with
//   deformability. Using c_max of the slowest material (d = 0) for the rate keeps D as the depth at which all
//   materials are fully hardened, and lets d act.
//
// Yield (how far a loaded vertex sinks in a step). After the solve (post step), each contact point's normal
// force on the terrain, projected on the field's +z, is split onto the three vertices of the height-field
// triangle under the point by its barycentric weights; the points' normal stiffnesses (their Young's moduli E,
// N/m) are split the same way. Each vertex keeps the moving average of both over the load averaging time
// (setLoadAveragingTime, 0.1 s): F_v and K_v (why: the setter's comment; a steady load is its own average). A
// vertex loaded in this step has pressure p_v = F_v / A, A = dx dy. Loose soil yields
// at p0 (the yield pressure); a vertex with multiplier m yields at p_y = p0 m. If p_v > p_y the vertex is
// lowered by the dz that solves
//     p0 A m(c + dz log2(M) / D) + K_v dz = F_v                       (implicit: a return mapping)
// i.e. it sinks until the force its contacts still carry once they relax by dz (F_v - K_v dz, the bodies held
// for the step) equals the yield force of the ground made harder by that sinking. The bodies then follow under
// their loads and the next steps continue, so a steady load ends where p0 m = p_v: the settled state is the
// one of "lower by exactly the dz that brings p_y up to p_v". Why not that explicit rule itself: a vertex that
// sinks dz sheds K dz of load onto its neighbours, and sinking by the full target makes the load exchange of
// neighbouring vertices under one body an iteration with gain K D / ((d+1) ln(M) F) - about 70 for a 52 N point
// with K = 1e5 N/m - which diverges (gain > 2): the ground under a plate or a wheel breaks into pits and
// spikes. The implicit rule never sheds more than the load (dz <= F_v / K_v, the contact's elastic
// deflection), so its updates are stable. Consequence: a vertex yields at most the elastic deflection
// F / (E m) of its contacts per step - give soil contacts a soil-like Young's modulus (per contact point, e.g.
// 1e5-1e6 N/m for centimetres of sinkage in a second); with stiff contacts (the 4e8 default) the ground
// compresses by micrometres per step.
// Bounds: the multiplier may grow by at most maxChange (the max Young's change per time step) in one step,
// which bounds dz too (maxChange = 0 freezes the ground); c is capped at c_max. Unloading changes nothing: the
// vertex keeps c, so a second pass at the same load meets ground that already carries it and only deflects
// elastically (the contact's stiffness is E m).
//
// Settled sinkage of a flat plate. Under a uniform pressure p on loose, level soil every vertex settles where
// p0 m = p, i.e. at depth
//     z* = D ln(p / p0) / ((d+1) ln M)         for p0 < p <= p0 M      (0 for p <= p0),
// finite, growing with load (logarithmically), falling as 1/(d+1) with deformability. Above p0 M (c at c_max,
// m = M) nothing balances the load: bearing failure - the vertex keeps sinking every step it is loaded, by the
// elastic excess (F_v - p0 A M) / K_v per step (and at most D log2(1 + maxChange / M) / ((d+1) log2 M)). The
// plastic sinkage is the height lost; the body rests an elastic F_v / (E m) deeper.
//
// Line contacts are line loads (model/src/terrain_line_load.cpp). A lying cylinder (a wheel) or capsule touches
// a plane-like field along a generator line, and the narrowphase reports that line by its two end points (at the
// tire's side edges; docs/terrain.md "Wheels on the height field"). Splitting those two point forces onto the
// triangles under the points would compress the soil only under the side edges, while the manual's per-vertex
// compression (25.1.2.1) describes the ground under what rests on it: a wheel compresses the soil under its whole
// width, as the rut it leaves shows. So the loaded points of one contact of a lying cylinder or capsule (axis
// within 60 degrees of the field's plane; two or more points) are read as one line load along the axis, over the
// points' axial extent, on the line through their force centroid parallel to the axis: a linear density q(t),
// t in [0, 1], whose total and moment equal the points' (sum F_i and sum F_i t_i: a linear density with those two
// is unique), so the total and the moment about every horizontal line are kept. Why the whole contact and not
// each generator line's end points alone: once the soil under a wheel is a rut, its line of contact comes in
// pieces (one per triangle, the joins no longer flat) with points on the rut's walls, and the narrowphase keeps
// the 4 deepest points, which need not be the line's ends (measured: a 1 m cylinder then sank 17.6-23.3 mm along
// its length, end rows as deep as the middle; read as one line over the contact's extent, 21.9-22.7 mm). Two
// different end forces F0, F1 give q(0) = 4 F0 - 2 F1, q(1) = 4 F1 - 2 F0 (per unit t). Soil carries no tension:
// when the resultant lies outside the segment's middle third (q would go negative at one end), the density is
// the triangle that starts at zero inside the segment and keeps the same total and resultant (the "middle third"
// rule of a footing's bearing pressure). The points' normal stiffnesses are spread the same way (total sum E_i,
// centroid sum E_i t_i), so every vertex under the line gets F_v / K_v = the points' elastic deflection and yields
// by the same implicit rule. The density is integrated exactly against the barycentric weights of every
// triangle the segment's footprint crosses (the weights are linear along the segment between crossings of grid
// lines and diagonals, q too between its own kink, so Simpson's rule on each piece is exact): the per-vertex loads
// add up to the points' load and their moment about any point equals the points' moment, to rounding. Points of
// other shapes (a sphere's one point, boxes' face corners, convex hulls), single points and deformer contacts are
// split at the point as before. Not done: a box's or an upright cylinder's 4-point face patch still loads the
// triangles under its corners only.
//
// Contact stiffness. A contact listener (contacts of any geometry with the terrain geometry) sets each point's
// Young's modulus to E * m, m interpolated barycentrically from the three vertices under the point, E the
// contact's (or the point's earlier override). The material of the nearest of those vertices picks the contact
// parameters: for a registered material other than the terrain geometry's own, the point's Young's modulus,
// friction, restitution and damping come from the contact material of (other geometry's material, vertex
// material). A point with m = 1 over the geometry's own material is left untouched: with d = 0 everywhere the
// terrain is bit-identical to a plain HeightField.
//
// Locked borders (25.1.2.5): setEnableLockedBorders(true) keeps every border vertex (x = 0, x = nx-1, y = 0,
// y = ny-1) at its height through compression and every other terrain edit.
//
// Volume ledger. getVolumeLedger() accounts for all soil, m^3: heightField = sum of height x vertex area over the
// grid (trapezoid weights: dx dy inside, dx dy / 2 on edges, dx dy / 4 at corners), kept incrementally: a
// vertex lowered by dz moves area * dz from heightField to compressed (soil made denser, not removed). The other
// accounts (particles, pending, lostAtBorder, removed) are filled by digging and avalanches; total() is
// constant through every terrain operation. Heights edited directly on the HeightField (not through the
// terrain) are not soil the terrain moved: the heightField account follows them at the next step or read
// (recomputed over the grid once, from the field's dirty rectangle) and the total changes by their volume.
//
// Cost. Per step the terrain reads the simulation's contact list; with nothing touching it that is all (no pass
// over the grid). Loaded vertices are gathered in a sparse list, load averages live on a sparse active list
// (a vertex leaves it about 1 s after its last contact), and height edits go through batched local HeightField edits
// (begin/endHeightEdit, one batch per cluster of nearby vertices), so only the touched tiles' bounds are updated.
//
// ---------------------------------------------------------------------------------------------------------------
// Dynamic height field: avalanches and the angle of repose (manual 25.1.2.15, 25.1.2.19, 25.1.2.20)
// ---------------------------------------------------------------------------------------------------------------
// setEnableDynamicHeightField(true) turns avalanches on (off by default). Deformer contacts (geometries with the
// bool property DynamicHeightFieldDeformer) are rebuilt and deformers push soil: the "deformers" section below.
// Avalanches are armed by merging particles, by deformers and by armAvalanche(x, y). avalancheAll() works either way.
//
// Arming. A vertex is armed for the avalanche step life time L (setAvalancheStepLifeTime, steps) when a particle
// merges into it (its three vertices; later also where a deformer touches), or when armAvalanche(x, y) is called
// (not in the manual: for user edits and tests). Arming a vertex also arms every vertex within the vertex
// distance extent e (setAvalancheVertexDistanceExtent; the manual's misspelt setAvalanceVertexDistanceExtent too)
// counted in vertices along x and y: the (2e+1) x (2e+1) square around it, clipped to the grid - the vertices
// reachable in e hops over the 8-neighbour links the avalanche uses. Re-arming an armed vertex restores L (the
// larger life wins). Arming does nothing (returns 0) while the dynamic height field is off.
//
// The pass (post step, after compression; once per step). Each armed vertex v with k steps left looks at its 8
// neighbours n (x, y and diagonal; 8 rather than 4 so that diagonals obey the repose limit too - with 4, a
// diagonal pair could stand at 2 tan(theta) s over s sqrt2, 41 % steeper). For the pair, with `hi` the higher
// and `lo` the lower vertex, ell the distance (dx, dy or sqrt(dx^2 + dy^2)) and theta = theta(hi), the angle of
// repose of the uphill vertex (the soil that would slide),
//     excess = (h_hi - h_lo) - tan(theta) ell.
// If excess > 0 (above a rounding tolerance of 1e-12 ell + 1e-14 (|h_hi| + |h_lo|)), the volume
//     V = 2 decay excess A_hi A_lo / (A_hi + A_lo)            (A: trapezoid vertex areas, as in the ledger)
// moves from hi to lo: h_hi -= V / A_hi, h_lo += V / A_lo. Volume, not height, is conserved (edge and corner
// vertices hold 1/2 and 1/4 of an inner vertex's area). With equal areas each vertex moves decay x excess,
// so decay 0.5 (the manual's maximum) leaves the pair exactly at the repose difference in one step and decay 0
// moves nothing (the manual: "at 0 there will be no avalanches"). Pairs are taken one after the other with the
// heights as they are (Gauss-Seidel): a vertex with several lower neighbours gives to each in turn, never more
// than brings that pair to repose, so no pass overshoots into a reversed slope steeper than the one it removed
// (each move lowers the potential energy; the process cannot cycle). The moves arm both vertices of the pair
// with k - 1 steps (unless they have more), so an avalanche spreads as far as the soil runs but dies out L
// steps after the arming that started it: an arming runs exactly L passes. Then v has k - 1 steps left.
//
// Locked borders. A locked border vertex never changes height: it gives no soil, and soil moving onto it is
// held back (no move) or, with avalancheMassLoss (setEnableLockedBorders' second argument, default true), lost
// over the border: V = 2 decay excess A_hi leaves hi (so decay 0.5 brings hi to repose against the fixed border
// height) and is booked heightField -> lostAtBorder. Without locked borders the border vertices are ordinary
// vertices and no soil leaves the grid.
//
// Compression of moved soil. The receiving vertex gets fresh loose soil on top: its c falls by
// dz log2(M) / D (dz = V / A_lo; not below 0), as for merged particles. The giving vertex keeps its c: an
// avalanche strips the loose top layer and does not compact what lies beneath (lowering by digging or
// pressing does raise c - they remove or press soil, a slide does neither).
//
// The angle of repose. theta0 = the material's angleOfRepose (TerrainDataInterface::add), or atan(mu) of the
// vertex material's friction coefficient (Material::getFrictionCoefficient; an infinite mu gives pi/2: it
// never slides) when that is 0. Wetness w (setWetnessScale, in [0, 1], default 0) makes compacted soil stand
// steeper, linearly in the compression relative to max compression (manual 25.1.2.20):
//     theta(c) = theta0 + w (c / c_max) (pi/2 - theta0) / 2         (c / c_max clamped to [0, 1])
// i.e. fully compacted, fully wet soil stands halfway between its dry angle and vertical (dry sand 34 deg ->
// 62 deg), never past pi/2; w = 0 (dry) or non-deformable ground (d = 0 or M = 1, c_max = 0) keeps theta0 at
// every compression. computeAngleOfRepose(x, y) returns the angle the pass uses at a vertex.
//
// avalancheAll(maxIterations) relaxes the whole field to repose now (imported or user-made terrain): passes
// over a work list, starting with every vertex, with the full move (decay 0.5, whatever the set decay), each
// pass holding only the vertices whose height changed in the previous one; it stops when a pass moves nothing
// (converged: every pair within repose up to the rounding tolerance) or after maxIterations passes. Locked
// borders and mass loss apply; nothing is armed.
//
// Cost. Armed vertices live in a sparse list (each with its steps left); a step's pass visits them and their 8
// neighbours, nothing else - no pass over the grid unless avalancheAll is called. Height edits are batched by
// cluster as for compression, so only the touched tiles' bounds are updated.
//
// ---------------------------------------------------------------------------------------------------------------
// Dynamic height field: deformers (manual 25.1.2.15-25.1.2.18; terrain_deform.cpp)
// ---------------------------------------------------------------------------------------------------------------
// A deformer is a geometry with the bool property DynamicHeightFieldDeformer (Terrain::DeformerProperty); its
// value is useContactDepth. While the dynamic height field is on, every contact of a deformer with the terrain
// is rebuilt in the contact listener (after the compression law has set each point's E):
//   - the overlap. From the deformer's world bounding box, taken into the field's frame: the footprint is the
//     vertices inside its x-y extent, z_min its bottom. A_v = dx dy x (footprint vertices whose height exceeds
//     z_min), the area of soil it overlaps seen from above. A_h = w x t, w = the box's width across the
//     horizontal direction d, t = how deep its bottom lies below the highest vertex of the footprint grown by
//     one vertex (the soil just ahead counts), at most the box's height. d = the horizontal velocity of the
//     deformer's body at the box centre, else the mean horizontal part of the contact normals (toward the
//     deformer), else none. Why the box: exact for an axis-aligned box (a blade, a plate), conservative for
//     other shapes, and the deformation below reads the same overlap, so both halves agree.
//   - per original point p, a vertical point (along the field's +z, featureId ^ 0x40000000, friction mu = p's)
//     with depth = p.depth |n.z| when useContactDepth is true (the penetration vector projected on the
//     vertical), else 0, and E_v = E max(1, A_v / s_v);
//   - and, when d exists and t > 0, a horizontal point (normal -d on the deformer: the soil resists the motion,
//     friction 0, featureId ^ 0x80000000) with depth 0 (the manual: nonzero horizontal depths push in opposite
//     directions and fail the solver) and E_h = E max(1, A_h / s_h) - the same law as the vertical one, as the
//     manual says ("works precisely as the vertical"; the project's design notes asked for a nonlinear f(A_h/s_h),
//     but the manual's section names no nonlinearity and its FAQ - a lower scale gives stiffer contacts - holds
//     for this law, so we keep the manual's); a zero-depth contact resists the approach velocity
//     with a compliance 1/E_h, so the resistance grows with the submerged frontal area, i.e. with depth;
//   - the original point keeps its friction and gets E kDeformerSoftness (1e-3 E): very soft.
// Friction. The manual has the very soft original contact "handle the friction". The solver bounds a point's
// friction rows by that point's own normal impulse, and the original point, 1e-3 as stiff as the vertical one,
// carries about 1e-3 of the load: alone it would grip with mu x 1e-3 of the weight (a resting deformer slid off
// under any push). So the vertical points carry the friction too, with the original point's mu: the contact's
// friction bound is mu (N_v + N_o), mu times the load the vertical points carry (plus the original's small
// share) - Coulomb's law on the load, in the same solve (no lag from a last-step force). Their friction rows lie
// in the field's horizontal plane; the original points keep theirs in the real surface's tangent plane. The
// horizontal points have none (they stand for soil pushed, not for a surface sliding).
//
// A shovel that is also a deformer (the manual's recommended set-up for buckets: 25.1.2.13, 25.1.2.15). Both
// parts act on it, each as for a plain shovel or deformer, in the order of the step: the cut (pre-collide) lowers
// its footprint and lead to the cutting plane (never below the box's bottom) and books heightField -> pending;
// the deformer contact rebuild (contact listener) and the push (post step) then see those lowered heights and
// move only soil still above the box's bottom (a bucket whose bottom lies below its cutting plane pushes that
// layer ahead, where the next step's cut takes it). Each operation reads the heights as the previous one left
// them and books only its own moves (the cut heightField -> pending, the push nothing: heightField to
// heightField), so the same soil is never counted twice and the ledger stays exact.
// Its ground cutting force (TerrainDataInterface::setShovelGroundCuttingForce, F in N) is a friction force in
// the forward direction (the manual: "a constant friction force in the shovel forward direction"): one
// velocity row of the terrain's own (Terrain::CuttingConstraint, terrain_shovel.cpp) on the relative velocity
// of the shovel and the terrain at the cutting edge (the tip) along the unit forward direction (world), target
// 0, impulse bounds +-F h, solved iteratively with the step's other rows. It is armed on a step where the
// shovel's body touches the terrain (the contact listener saw an enabled contact with points) and F > 0,
// otherwise it has no row; like contact rows it acts only on a dynamic body (a kinematic path ignores forces). So: moving along forward (or backward) the shovel meets exactly F against the
// motion; held, it stays put while the other forces along forward stay below F; sliding sideways it meets
// nothing from it (a row along forward does not see motion across it). Why a row and not the friction rows:
// those act in every tangential direction, and raising their coefficients by F / N (the first reading) gave F
// against any sliding, sideways too. The force is read back as TerrainShovelStats::groundCuttingForce.
// s_v, s_h: setVerticalYoungsModulusAreaScaler / setHorizontalYoungsModulusAreaScaler (m^2, finite, > 0;
// defaults 0.01, the manual's example, and 0.005, lower than the vertical as the manual's rule of thumb says).
// E is the point's E after compression (the contact material's E x m(c)).
//
// Deformation (post step, after compression, before avalanches). A deformer in contact this step whose body
// moves faster than the cut-off velocity at its box centre, or turns faster than the cut-off angular velocity
// (setDynamicHeightFieldCutOffVelocity / ...AngularVelocity, >= 0; defaults 0.05 m/s, 0.05 rad/s), pushes
// away the soil it overlaps: each footprint vertex with excess e = h - z_min > 0 (not a locked border vertex)
// is lowered by e, and its volume V = e A_src goes to the first vertex outside the footprint along the
// horizontal velocity of the body at that vertex (1/2), and along that direction turned by +-45 deg (1/4 each):
// ahead and to the sides, a berm. A target off the grid, inside the footprint or on a locked border gives its
// share to the other targets; with none the vertex is left. Heights only move between vertices (h_t += share
// V / A_t), so the ledger's heightField account is unchanged: volume conserving. Compression: the pushed
// vertex's c rises by e log2(M) / D (soil pushed away, as digging), a receiver's c falls by its rise (fresh
// loose soil). Every moved vertex (source and targets) is armed for avalanches (armWithExtent, the life time),
// so the berm slumps to its angle of repose. Below both cut-offs nothing is edited (heights bit-identical).
//
// ---------------------------------------------------------------------------------------------------------------
// Digging (manual 25.1.1.2, 25.1.2.6-25.1.2.9, 25.1.2.12; implemented here: shovels, the cut, particles, merging)
// ---------------------------------------------------------------------------------------------------------------
// Shovels. Any geometry in the simulation (on a body or static) with both Vec3 properties ShovelUpProperty and
// ShovelForwardProperty (getPropertyContainer().addPropertyVec3) is a shovel; several may dig at once. Both
// vectors are in the geometry's local frame: forward's length is the distance from the geometry's origin to the
// cutting edge (the tip, origin + forward), up's length is the blade thickness; up must be orthogonal to forward
// and point "up in the air" when the shovel rests on the ground. There is no setter to throw from, so a bad pair
// (a zero or non-finite vector, |cos(up, forward)| > 1e-6, or a property of another type) is reported when the
// terrain first sees the geometry - one Logger error naming the geometry and the problem - and the geometry is
// not a shovel (isGeometryShovel is false, nothing is dug); fix the properties and it digs from the next step.
//
// The cut (a pre-collide step listener, before the step's contacts are found). Per shovel, in the height field's
// frame: the cutting plane passes through the tip with normal up. Where the shovel is upside down (up has no
// component along the field's +z, i.e. against gravity) or up makes less than the minimum dig angle with the
// horizontal plane (setShovelMinimumDigAngleToHorizontalPlane, default pi/10) nothing is cut. Reading: the
// manual's angle guards against a shovel whose forward points (nearly) straight down, where the cut is a crack
// no particle fits in; up's angle to the horizontal plane is exactly forward's angle away from straight down
// (forward's elevation is up's complement), so a level blade (forward horizontal, up vertical) digs best.
// Footprint: the vertices inside the shovel geometry's world bounding box projected on the field, the box reaching
// a lead of one cell plus one particle diameter (max(dx, dy) + 2r) further on the side of the cutting edge (the
// direction from the box's centre to the tip, seen from above). Why the lead: the uncut ground next to the cut is
// a slope one cell wide, a rigid wall; without the lead it stands within a cell of the edge, and particles the
// blade pushes wedge between the blade and that wall and jam, loading the blade with forces that grew with the
// solver's iterations and with smaller time steps (a 1 cm blade in the FEE study gave 33, 50 and 88 N for 30 and
// 60 iterations and half the step, docs/terrain.md); with the wall a particle diameter clear of the edge they rise instead
// (10.3, 10.8, 14.1 N), as loosened soil in front of a real blade does. Particles are made over the box only (below;
// with the failure wedge on, over the whole cut):
// the lead's volume stays pending until the box passes over it (where a shovel stops, the trench runs a lead
// further than the box went and that strip stays pending). Each footprint
// vertex whose height lies above the cutting plane - and above the box's lowest point: the shovel never cuts
// deeper than it reaches - is lowered to it; the volume (vertex area x dz) moves heightField -> pending at that
// vertex, and c rises by the compression rule above (a deformable vertex gets harder as it is dug deeper).
// Locked border vertices are never cut.
//
// The failure wedge (setShovelFailureWedge, default off; issue 16's FEE study, docs/terrain.md). With it on, a
// plain shovel's cut (not a deformer's: a deformer pushes the soil ahead as compression and a berm) also takes
// the soil in front of the lead that lies above the failure plane of the fundamental earthmoving equation: the
// plane rises at beta* (failureWedgeAngle: the FEE's minimising angle for the shovel's rake - the cutting
// plane's angle from the horizontal - the soil's phi = atan(friction of the material of the vertex nearest the
// tip) and delta = atan(friction of the shovel's material with that material)) from the box's lowest point at the
// lead's front, in the horizontal direction from the box's centre to the tip, up to the height of the box's top;
// across it, the footprint's (axis-aligned) extent as for the lead. The soil it takes goes heightField -> pending
// as any cut, and particles are made over the whole cut (box, lead and wedge: sites lie over that rectangle, not
// only over the box); the cap (below) reaches at least the wedge's far top edge (where the failure plane meets
// the ground), so the wedge's sites may stand where its soil stood - a bare blade's cap (its box's top corner
// along up) fell short of that at a steep rake and a deep cut (60 degrees, 7 cm: 0.16 m against 0.18 m) and the
// far part of the wedge stayed pending, soil the blade never met. Why: the manual cuts "the volume above the cutting surface inside the footprint", and
// with a rigid height field ahead of the edge nothing fails in front of a blade: a blade then pushes only what it
// has already cut, a force that grows with travel and linearly with depth (the FEE's surcharge term), and the
// FEE's gamma d^2 w N_gamma - the weight and shear of the wedge - is missing (docs/terrain.md measured it at 0.02-
// 0.5 of the FEE). Taking the wedge as particles makes the soil the FEE fails a body of particles the shovel must
// lift up the failure plane (the height field, soil friction) - the FEE's mechanism - with its volume ~ d^2 w.
// The toe starts at the lead's front, not at the edge, so the floor is continuous (a step there would be the
// wall the lead removes). Why off by default: the read-outs and tests of buckets assume particles are made over
// the box (the fill is "the particles the cut made"), and a bucket's rake (its up nearly vertical) gives a long,
// shallow wedge that turns ground the bucket never reaches into particles.
//
// Particles (25.1.2.7-25.1.2.9). Pending volume becomes particles on a face-centred cubic lattice fixed in the
// field's frame (anchored at vertex (0, 0), z = 0), nearest neighbours at d = 2r - r(sqrt2 - 1) = r(3 - sqrt2),
// i.e. they overlap by exactly the manual's adhesive overlap r(sqrt2 - 1); the cube side is a = sqrt2 d and each
// site stands for a^3 / 4 of space. At the default radius r = s / (2(3 sqrt2 - 2)) (s the smaller cell size)
// the cube is half a cell: the lattice is at twice the height-field resolution. Every particle carries exactly
// V = a^3 / 4 of soil (getParticleVolume()) taken from the pending volume of the vertex whose cell column holds
// its site; volume that does not yet fill a particle stays pending at its vertex. A site is used when it lies
// over the digging shovel's footprint (its bounding box seen from above), at least r above the shovel plane (the cutting plane moved up by
// the blade thickness, |up|), at least r above the vertex's height, and no terrain particle is closer than d.
// The lowest free sites (nearest the shovel plane) fill first. Pending volume outside a digging shovel's
// footprint stays pending.
// The cap (issue 16: a full bucket grew a column of new particles over its front edge). A site's centre stands
// at most `top - r` above the shovel plane, where top is the highest point of the shovel's body - every geometry
// on it, the shovel included (a bucket's back and side plates) - along up, taken from the corners of their world
// bounding boxes: a made particle lies below the bucket's rim. A bare blade (nothing on its body reaches 2r above
// the shovel plane: no rim to fill to) caps at its footprint's larger horizontal side instead, the height the
// fill read-out also allows above it (TerrainShovelStats). Once a vertex's sites below the cap are taken, its
// pending volume stays pending: the cut goes on, so a full bucket dragged on leaves a trench whose soil waits in
// the ledger's pending account (at the vertices it passed: getVolumeLedger().pending) and becomes particles when
// a shovel with free sites passes over it again. Why pending and not "stop cutting": the cut then keeps its
// geometry - the lead, which keeps the uncut wall a particle diameter clear of the edge; a full bucket that
// stopped cutting would push its edge into that wall, the jam whose forces grew with the solver's iterations
// (above) - and the ledger stays exact with no new transfer (pending -> heightField). The cost: soil a full
// bucket cuts is not shown as soil (no berm in front of it) until something digs there again. The particle's material is a new material with the vertex material's surface
// parameters and a density chosen so that its mass is exactly the bulk density (the vertex material's density)
// x V; a contact material of it with itself gives particle-particle contacts the vertex material's parameters
// and the adhesion (the index's particleAdhesion, rest overlap r(sqrt2 - 1); with particle adhesion 0 a
// negligible 1e-9 N, since the contact law applies the rest overlap only to adhesive contacts); its carried volume is also in
// the particles' custom buffer ParticleVolumeBuffer. Its velocity is the shovel's at the site.
//
// Merging. A terrain particle slower than the merge velocity (setMergeVelocity, default 0.1 m/s), over the
// field, resting near it (its bottom within one diameter of the surface under it) and outside every shovel's
// non-merge zone (the shovel's bounding box grown by one diameter) returns its volume to the three vertices of
// the triangle under it by the barycentric weights (locked border vertices excluded, the weights renormalised;
// a vertex rises by its share / its area, c falls by the compression rule, not below 0), and is destroyed:
// particles -> heightField. A terrain particle the user destroys moves its volume particles -> removed.
//
// External materials and particle solve type (manual 25.1.2.10, 25.1.2.11, 25.1.2.14; FAQ 25.1.3.2, 25.1.3.4;
// terrain_particle_materials.cpp). Every terrain-particle material (one per source material, radius, particle
// adhesion and density) has explicit contact materials in the simulation's MaterialManager, rewritten whenever a
// setting below changes - also for the particles that exist:
//   * with itself: the source material's parameters, E = source E x the particle Young's multiplier
//     (TerrainParticleAttributes, default 1), and per the particle friction solve type
//     (TerrainDataInterface::setParticleFrictionSolveType):
//       ITERATIVE (default): the particle adhesion (1e-9 N when 0, see above) at rest overlap r(sqrt2 - 1).
//       DIRECT: friction and adhesion infinite, solve type DIRECT, surface viscosity = the inverse friction
//         multiplier (default 1) x the source material's surface viscosity; the particle DIRECT mode of the
//         solver glues the lump (every bond an equality row: one factorisation, no pivot for the bonds). The
//         rest overlap stays the lattice's r(sqrt2 - 1), not the manual's 0: in Scree the bonds need no pivot
//         because their bounds are infinite, whatever the overlap, while a rest overlap of 0 would push every
//         lattice bond from r(3 - sqrt2) apart to 2r - the lump would swell by 26% in size (2x in volume) the
//         moment it is dug. Also in DIRECT, the particles' contacts with the terrain geometry's material and
//         with external materials are ITERATIVE: the direct solve then holds only equality rows (no pivot, as
//         the manual requires of this mode), and the solve stage alternates it with the particle sweeps over
//         those contacts and ends the step with it, so the lump's velocities satisfy its bonds
//         (solver/src/solve_stage.cpp, lumpPath; docs/terrain.md). DIRECT still needs the shovel registered as
//         external (otherwise the soft soil combination is met, as in the FAQ failure).
//       SPLIT and DIRECT_AND_ITERATIVE are rejected: with infinite friction their friction rows would be
//         unbounded PGS rows.
//   * with every external material (TerrainDataInterface::addExternalMaterial, the bucket's steel): the
//     parameters with which the source material meets it (the user's explicit contact material of the two, or
//     the combination), with E = max(E_external, E_source), solve type SPLIT (ITERATIVE in the DIRECT particle
//     mode, above; PGS without SuiteSparse, as everywhere) and the external material's surface viscosity (the bucket sets how friction on it yields,
//     whatever soil slides on it). removeExternalMaterial unregisters them.
// Why: particles meet everything else through the combination with the soil's own, soft, parameters - the
// manual's FAQ failure: they sink into and fall through the bucket, and newly made particles tunnel through the
// blade. A terrain particle touching a geometry whose material is not external logs one Logger warning per
// material (naming it, the geometry and addExternalMaterial); the check runs in the terrain's contact listener
// over the step's particle-geometry contacts and returns at once while the terrain has no particles.
//
// The shovel read-outs (digging force, fill) and the ground cutting force are below (TerrainShovelStats).
// A DIRECT lump dug and carried by a bucket moves as one body: its glued clusters are integrated by their rigid
// motion (GranularStage::integrateBondedLumps; docs/terrain.md, "The DIRECT lump carry").
#pragma once

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "scree/collide/geometry.h"
#include "scree/collide/shapes.h"
#include "scree/core/listeners.h"
#include "scree/model/terrain_data_interface.h"
#include "scree/solver/model.h"

namespace scree {

/// Where the terrain's soil is, m^3 (see terrain.h). total() is conserved by every terrain operation.
struct TerrainVolumeLedger {
  Real heightField = 0;   ///< sum of height x vertex area (trapezoid weights)
  Real compressed = 0;    ///< pressed out of the height by compression (denser soil, not removed)
  Real particles = 0;     ///< carried by live terrain particles (digging)
  Real pending = 0;       ///< removed by a shovel, not yet a whole particle (digging)
  Real lostAtBorder = 0;  ///< avalanched over a locked border with mass loss on
  Real removed = 0;       ///< particles destroyed by the user or that left the simulation
  Real total() const { return heightField + compressed + particles + pending + lostAtBorder + removed; }
};

/// What avalanches did: in the last step's pass (Terrain::getLastStepAvalancheStats) or in one avalancheAll call.
struct TerrainAvalancheStats {
  size_t passes = 0;       ///< passes over the armed (or work) list
  size_t visited = 0;      ///< vertex visits over all passes
  size_t moves = 0;        ///< pair moves (soil moved from a vertex to a neighbour or over a locked border)
  Real volumeMoved = 0;    ///< m^3 moved between vertices
  Real volumeLost = 0;     ///< m^3 lost over locked borders (heightField -> lostAtBorder)
  bool converged = false;  ///< avalancheAll: the last pass moved nothing (every pair within repose)
};

/// What digging did in the last step (see the file comment).
struct TerrainDigStats {
  size_t particlesCreated = 0;  ///< particles made from pending volume
  size_t particlesMerged = 0;   ///< particles merged back into the height field (and destroyed)
  size_t particlesRemoved = 0;  ///< terrain particles found destroyed by someone else (volume booked removed)
  Real volumeDug = 0;           ///< m^3 cut out of the height field (heightField -> pending)
  Real volumeMerged = 0;        ///< m^3 merged back (particles -> heightField)
};

class Terrain;

// ---------------------------------------------------------------------------------------------------------------
// Shovel read-outs (manual 25.1.1.2; model/src/terrain_shovel.cpp). After each step's solve the terrain's
// post-step listener records, for every valid shovel geometry in the simulation (any geometry the digging
// treats as a shovel, whether it touched anything or not):
//   terrainContactForce   sum over the enabled, non-sensor contact points between the shovel geometry and the
//                         terrain geometry of the force the solver applied on the shovel (normal + friction,
//                         world frame, N; adhesion pulling counts with its sign).
//   groundCuttingForce    the ground cutting row's force on a shovel that is also a deformer (world, N; along
//                         forward, |.| <= F; zero otherwise). diggingForce() sums the three forces.
//   particleContactForce  the same over the particle-geometry contacts between the shovel geometry and the
//                         live particles this terrain made (GranularBodySystem contact lists: the force on the
//                         particle is normalForce * normal + frictionForce, the shovel feels its negative).
//                         Particles of other origin are not counted.
//   fill                  the terrain particles whose centre lies (a) inside the fill box: the union B of the world
//                         bounding boxes of all geometries on the shovel's body (the shovel geometry's own box
//                         for a static shovel; a bucket's plates together bound its inside), with its top raised
//                         by B's larger horizontal side, and (b) on the up side of the shovel plane (the cutting
//                         plane through the tip moved up by the blade thickness: the plane particles are created
//                         above). fillVolume sums their carried volumes (m^3), fillParticles counts them.
//                         Why a box: a shovel is any set of geometries; the box is defined for all of them and its
//                         horizontal extent is the footprint the cut uses. Why raised: a flat blade's own box is
//                         as thin as the blade, and a heap on a footprint of side s stands lower than s for any
//                         repose angle below 63 degrees, so the raised box holds what a blade or bucket carries.
//                         (b) keeps out what lies under or behind the blade. World z is taken as up.
// Geometry poses are this step's final ones (after integration). A shovel that is not valid (or no longer in
// the simulation) has no entry; getShovelStats then returns zeros with `shovel` set.
// ---------------------------------------------------------------------------------------------------------------
/// Per shovel, last step (see the file comment): forces on the shovel (world frame, N) and its fill.
struct TerrainShovelStats {
  const Geometry* shovel = nullptr;
  Vec3 terrainContactForce = Vec3::Zero();   ///< from contacts with the terrain geometry
  Vec3 particleContactForce = Vec3::Zero();  ///< from contacts with terrain particles
  Real fillVolume = 0;                       ///< soil volume of the terrain particles in the shovel (m^3)
  size_t fillParticles = 0;
  /// The ground cutting force's row on a shovel that is also a deformer (TerrainDataInterface::
  /// setShovelGroundCuttingForce): along forward, |.| <= the set force; zero for other shovels.
  Vec3 groundCuttingForce = Vec3::Zero();
  Vec3 diggingForce() const { return terrainContactForce + particleContactForce + groundCuttingForce; }
};

/// Particle attributes of a terrain (manual 25.1.2.8): the radius of particles made from now on.
class TerrainParticleAttributes {
 public:
  explicit TerrainParticleAttributes(const Terrain& t) : terrain_(t) {}
  /// m, finite, > 0 and <= Terrain::getMaximumParticleRadius(); otherwise std::invalid_argument, unchanged.
  void setParticleRadius(Real radius);
  /// The set radius, or the default s / (2 (3 sqrt2 - 2)) (lattice at twice the height-field resolution).
  Real getParticleRadius() const;
  /// Particle-particle contact E = the vertex material's E x multiplier (manual 25.1.2.11); finite and > 0
  /// (default 1), otherwise std::invalid_argument, unchanged. Applies to the particles that exist too.
  void setParticleYoungsModulusMultiplier(Real multiplier);
  Real getParticleYoungsModulusMultiplier() const { return youngsMultiplier_; }

 private:
  const Terrain& terrain_;
  Real radius_ = 0;  ///< 0: the default
  Real youngsMultiplier_ = 1;
};

class Terrain : public Model {
 public:
  /// Makes a static geometry (material: none, i.e. the simulation's default until setMaterial) for the field.
  explicit Terrain(HeightFieldRef heightField);
  /// A geometry holding a HeightField; on a body it must have an identity local transform.
  explicit Terrain(GeometryRef terrainGeometry);
  ~Terrain() override;

  const GeometryRef& getGeometry() const { return geometry_; }
  const HeightFieldRef& getHeightField() const { return heightField_; }

  TerrainDataInterface& getDataInterface() { return *data_; }
  const TerrainDataInterface& getDataInterface() const { return *data_; }
  /// Replaces the data interface with a subclass built for this terrain (TerrainDataInterface(*this)); its
  /// state starts fresh. Null or one built for another terrain throws std::invalid_argument.
  void setDataInterface(std::unique_ptr<TerrainDataInterface> dataInterface);

  /// Border vertices keep their height (manual 25.1.2.5). avalancheMassLoss: soil avalanching over a locked
  /// border is lost (booked as lostAtBorder) instead of held back (used by avalanches).
  void setEnableLockedBorders(bool enable, bool avalancheMassLoss = true);
  bool getEnableLockedBorders() const { return lockedBorders_; }
  bool getAvalancheMassLoss() const { return avalancheMassLoss_; }
  bool isBorderVertex(size_t x, size_t y) const;

  /// The soil accounts; valid between steps and inside listeners, every step.
  const TerrainVolumeLedger& getVolumeLedger() const;
  /// Full-grid trapezoid sum of the heights (the debug check of the ledger's incremental heightField account).
  Real computeHeightFieldVolume() const;
  /// Trapezoid weight of vertex (x, y), m^2.
  Real getVertexArea(size_t x, size_t y) const;

  /// Presses vertex (x, y) down by depth (m, finite, >= 0) as compression does: the height drops, c grows by
  /// depth log2(M) / D (capped at c_max), the multiplier follows, and the volume moves from heightField to
  /// compressed. No per-step bound applies (this is not a step). Does nothing and returns false on a
  /// non-deformable vertex (d = 0 or M = 1) and on a locked border vertex. Use it to pre-compact ground (a
  /// road, last run's ruts) or to test the law.
  bool pressVertex(size_t x, size_t y, Real depth);

  /// Closed-form settled plastic sinkage (m) of loose level soil of deformability d under a uniform pressure
  /// (Pa) with this terrain's p0, M and D: 0 up to p0, +infinity above p0 M (bearing failure). See the file
  /// comment.
  Real computeSettledSinkage(Real pressure, Real deformability) const;

  /// The yield reads each vertex's load averaged over this time (s, >= 0; an exponential moving average; at most
  /// one step: no averaging). Why: a body that follows yielding ground lands on it with impulses ~ m v / h, one
  /// step long, which a yield law reading single-step forces takes for load and answers by yielding more - at
  /// small time steps a runaway. The time average of a contact force is the load it carries (momentum
  /// balance), so averaging over a few damping times removes the impulses and keeps the settled state. Cost: a
  /// load shorter than this time counts partly (a fast wheel compresses less; docs/terrain.md).
  static constexpr Real defaultLoadAveragingTime = 0.1;
  void setLoadAveragingTime(Real seconds);
  Real getLoadAveragingTime() const { return loadAveragingTime_; }

  // --- dynamic height field: avalanches and the angle of repose (file comment) ------------------------------------
  /// Turns the dynamic height field on or off (default off). On: deformer contacts are rebuilt, deformers push
  /// soil, armed vertices avalanche every step. Turning it off disarms every vertex.
  void setEnableDynamicHeightField(bool enable);
  bool getEnableDynamicHeightField() const { return dynamicHeightField_; }
  static constexpr int defaultAvalancheStepLifeTime = 100;
  static constexpr Real defaultAvalancheDecayPercent = 0.1;
  static constexpr int defaultAvalancheVertexDistanceExtent = 2;
  /// Steps an arming lasts (>= 0; 0: arming does nothing). Otherwise std::invalid_argument, unchanged.
  void setAvalancheStepLifeTime(int numSteps);
  int getAvalancheStepLifeTime() const { return avalancheLifeTime_; }
  /// Fraction in [0, 0.5] (finite): 0 no avalanches, 0.5 a single pair reaches repose in one step.
  void setAvalancheDecayPercent(Real decay);
  Real getAvalancheDecayPercent() const { return avalancheDecay_; }
  /// Vertices armed around an armed vertex, counted along x and y (>= 0).
  void setAvalancheVertexDistanceExtent(int numVertices);
  /// The manual's spelling of setAvalancheVertexDistanceExtent.
  void setAvalanceVertexDistanceExtent(int numVertices) { setAvalancheVertexDistanceExtent(numVertices); }
  int getAvalancheVertexDistanceExtent() const { return avalancheExtent_; }
  /// Wetness in [0, 1] (finite): 0 dry (the angle of repose is the same at any compression), 1 fully wet.
  void setWetnessScale(Real scale);
  Real getWetnessScale() const { return wetness_; }
  /// The angle of repose (rad) the avalanche uses at vertex (x, y): theta(c) of the file comment.
  Real computeAngleOfRepose(size_t x, size_t y) const;
  /// Arms vertex (x, y) and the vertices within the extent for the life time (not in the manual: for user edits
  /// and tests). Returns the number of vertices armed; 0 while the dynamic height field is off or L = 0.
  size_t armAvalanche(size_t x, size_t y);
  /// Steps of avalanching left at vertex (x, y) (0: not armed).
  int getAvalancheStepsLeft(size_t x, size_t y) const;
  size_t getNumArmedVertices() const { return armed_.size(); }
  /// Relaxes the whole field to its angle of repose now, in at most maxIterations (>= 1) passes. Works whether
  /// or not the dynamic height field is on; arms nothing.
  static constexpr int defaultAvalancheAllIterations = 100000;
  TerrainAvalancheStats avalancheAll(int maxIterations = defaultAvalancheAllIterations);
  const TerrainAvalancheStats& getLastStepAvalancheStats() const { return avalancheStats_; }
  /// Wall-clock time of the last step's avalanche pass, s (part of getLastStepTime()).
  double getLastStepAvalancheTime() const { return lastAvalancheTime_; }

  // --- dynamic height field: deformers (file comment; terrain_deform.cpp) -----------------------------------------
  static constexpr const char* DeformerProperty = "DynamicHeightFieldDeformer";
  static constexpr Real defaultVerticalYoungsModulusAreaScaler = 0.01;
  static constexpr Real defaultHorizontalYoungsModulusAreaScaler = 0.005;
  static constexpr Real defaultDynamicHeightFieldCutOffVelocity = 0.05;
  static constexpr Real defaultDynamicHeightFieldCutOffAngularVelocity = 0.05;
  /// Factor on the original contact point's E of a deformer contact (very soft: it carries the friction).
  static constexpr Real kDeformerSoftness = 1e-3;
  /// m^2, finite and > 0; otherwise std::invalid_argument, unchanged.
  void setVerticalYoungsModulusAreaScaler(Real scale);
  Real getVerticalYoungsModulusAreaScaler() const { return scalerV_; }
  void setHorizontalYoungsModulusAreaScaler(Real scale);
  Real getHorizontalYoungsModulusAreaScaler() const { return scalerH_; }
  /// m/s and rad/s, finite and >= 0; otherwise std::invalid_argument, unchanged.
  void setDynamicHeightFieldCutOffVelocity(Real cutOffVelocity);
  Real getDynamicHeightFieldCutOffVelocity() const { return cutOffV_; }
  void setDynamicHeightFieldCutOffAngularVelocity(Real cutOffAngularVelocity);
  Real getDynamicHeightFieldCutOffAngularVelocity() const { return cutOffW_; }
  /// E max(1, A / s_v) and E max(1, A / s_h).
  Real computeVerticalYoungsModulus(Real E, Real area) const;
  Real computeHorizontalYoungsModulus(Real E, Real area) const;
  /// True when the geometry carries the bool DynamicHeightFieldDeformer property.
  static bool isGeometryDeformer(const Geometry& g);
  /// One deformer contact of the last step, as the listener built it.
  struct DeformerContactInfo {
    const Geometry* geometry = nullptr;
    bool useContactDepth = false;
    Real verticalArea = 0, horizontalArea = 0;  ///< A_v, A_h, m^2
    Real youngsModulus = 0;                     ///< E of the first original point (after compression)
    Real verticalYoungsModulus = 0, horizontalYoungsModulus = 0;
    size_t numOriginalPoints = 0, numVerticalPoints = 0, numHorizontalPoints = 0;
  };
  const std::vector<DeformerContactInfo>& getLastStepDeformerContacts() const { return lastDeformerContacts_; }
  /// What deformation did in the last step.
  struct DeformStats {
    size_t verticesPushed = 0;
    Real volumePushed = 0;  ///< m^3 moved between vertices
  };
  const DeformStats& getLastStepDeformStats() const { return deformStats_; }

  // --- digging (file comment) ---------------------------------------------------------------------------------
  static constexpr const char* ShovelUpProperty = "ShovelUpProperty";
  static constexpr const char* ShovelForwardProperty = "ShovelForwardProperty";
  /// Name of the GranularBodySystem custom buffer holding each terrain particle's carried soil volume, m^3.
  static constexpr const char* ParticleVolumeBuffer = "TerrainParticleVolume";
  /// True when the geometry carries both shovel properties as valid Vec3 (nonzero, finite, orthogonal).
  bool isGeometryShovel(const Geometry& geometry) const;
  bool isGeometryShovel(const GeometryRef& geometry) const { return geometry && isGeometryShovel(*geometry); }
  /// Empty when (up, forward) is a valid shovel pair, otherwise why not (the text of the logged error).
  static std::string checkShovelVectors(const Vec3& up, const Vec3& forward);
  /// rad, in [0, pi/2]; otherwise std::invalid_argument, unchanged.
  void setShovelMinimumDigAngleToHorizontalPlane(Real angle);
  Real getShovelMinimumDigAngleToHorizontalPlane() const { return minDigAngle_; }
  /// m/s, finite and >= 0; otherwise std::invalid_argument, unchanged. 0 turns merging off.
  void setMergeVelocity(Real velocity);
  Real getMergeVelocity() const { return mergeVelocity_; }
  TerrainParticleAttributes& getParticleAttributes() { return particleAttributes_; }
  const TerrainParticleAttributes& getParticleAttributes() const { return particleAttributes_; }
  /// The largest particle radius accepted: the smaller cell size.
  Real getMaximumParticleRadius() const { return std::min(dx_, dy_); }
  /// Soil volume each particle carries at the current radius, (sqrt2 r (3 - sqrt2))^3 / 4, m^3.
  Real getParticleVolume() const;
  /// Nearest-neighbour distance of the particle lattice, r (3 - sqrt2).
  Real getParticleLatticeDistance() const;
  // --- the failure wedge of a plain shovel's cut (issue 16, FEE; file comment "The failure wedge") ---
  /// The fundamental earthmoving equation's failure-plane angle beta* (rad, from the horizontal) of a blade of
  /// rake `rake` (rad from the horizontal, clamped to [1e-3, pi/2]) in cohesionless soil of friction angle `phi`
  /// with soil-blade friction angle `delta`: the beta in (0, pi/2 - phi) that minimises N_gamma =
  /// (cot rake + cot beta) / (2 (cos(rake + delta) + sin(rake + delta) cot(beta + phi))); golden-section search
  /// to 1e-9 rad. Bad input (non-finite, phi outside [0, pi/2), delta outside [0, pi/2)) throws.
  static Real failureWedgeAngle(Real rake, Real phi, Real delta);
  /// Whether a plain shovel's cut also takes its failure wedge (file comment "The failure wedge"); default false.
  void setShovelFailureWedge(bool enable) { failureWedge_ = enable; }
  bool getShovelFailureWedge() const { return failureWedge_; }
  /// Pending volume at vertex (x, y), m^3.
  Real getPendingVolume(size_t x, size_t y) const { return pending_[y * nx_ + x]; }
  /// Ids (GranularBodySystem) of the live particles this terrain made.
  std::vector<size_t> getParticleIds() const;
  /// Soil volume carried by a terrain particle (0 for any other id).
  Real getParticleCarriedVolume(size_t id) const;
  const TerrainDigStats& getLastStepDigStats() const { return digStats_; }

  // --- shovel read-outs and ground cutting force (terrain_shovel.cpp; see TerrainShovelStats) ----------------
  /// One entry per valid shovel geometry of the last step, in the order the simulation lists them.
  const std::vector<TerrainShovelStats>& getLastStepShovelStats() const { return shovelStats_; }
  /// The shovel's entry of the last step; zeros (with `shovel` set) when it was not seen last step.
  TerrainShovelStats getShovelStats(const Geometry& shovel) const;
  // --- end shovel read-outs ----------------------------------------------------------------------------------

  /// Vertices loaded by contacts in the last step, and how many of them yielded.
  size_t getNumLoadedVertices() const { return numLoaded_; }
  size_t getNumYieldedVertices() const { return numYielded_; }

  // --- per-vertex loads of the last step (line loads, terrain_line_load.cpp) ----------------------------------
  /// One vertex's share of the contacts' normal load in the last step (before averaging): force along the
  /// field's +z (N) and normal stiffness (N/m), at grid vertex (x, y).
  struct VertexLoad {
    size_t x = 0, y = 0;
    Real force = 0, stiffness = 0;
  };
  /// Every vertex loaded by contacts in the last step (the loads the yield law reads, before averaging).
  const std::vector<VertexLoad>& getLastStepVertexLoads() const { return lastLoads_; }
  // --- end per-vertex loads ----------------------------------------------------------------------------------
  /// Wall-clock time of the terrain's own work in the last step (its pre-collide listener - digging: shovels,
  /// the cut, particle creation and merging - and its contact and post-step listeners), s.
  double getLastStepTime() const { return lastPreCollideTime_ + lastContactTime_ + lastPostTime_; }

 protected:
  void onAdd(Simulation& sim) override;
  void onRemove(Simulation& sim) override;

 private:
  class ContactListener;
  class StepListener;
  friend class TerrainDataInterface;
  friend class TerrainParticleAttributes;

  void init();
  /// Triangle under a height-field-frame point: the three vertex indices and barycentric weights. False outside.
  bool locate(const Vec3& pLocal, size_t (&v)[3], Real (&w)[3]) const;
  void modifyContact(GeometryContact& contact);
  void postStep();
  void preCollide();
  struct Shovel;
  void findShovels(std::vector<Shovel>& out);
  void mergeParticles(const std::vector<Shovel>& shovels);
  void cut(const Shovel& shovel);
  /// siteRect (field frame: loX, hiX, loY, hiY) replaces the shovel's box as the region sites may lie over when
  /// non-null (a plain shovel's lead and failure wedge).
  void createParticles(const Shovel& shovel, size_t i0, size_t i1, size_t j0, size_t j1,
                       const Real* siteRect = nullptr);
  MaterialRef particleMaterial(size_t v);
  // --- particle contact materials (terrain_particle_materials.cpp) ---
  struct ParticleMaterialCache;
  /// (Re)writes the particle-particle contact material of `c` and its contact materials with every external
  /// material, and unregisters those of external materials no longer registered.
  void syncParticleContactMaterials(ParticleMaterialCache& c);
  /// syncParticleContactMaterials for every particle material (after a setting changed).
  void syncParticleContactMaterials();
  /// The FAQ warning: a terrain particle touching a geometry whose material is not external (once per material).
  void checkParticleContacts(const std::vector<ParticleContact>& particleGeometry);

  // --- line loads (terrain_line_load.cpp) ---
  /// Adds force f and stiffness k to vertex v's load of this step (listing it in loaded_ on its first load).
  void addVertexLoad(size_t v, Real f, Real k);
  /// Splits one point's load (height-field frame point q) onto its triangle's vertices by barycentric weights.
  void depositPoint(const Vec3& q, Real load, Real E);
  /// Gathers the loads of one contact with the terrain (self: the terrain's index in it): the points of a lying
  /// cylinder or capsule as one line load along its axis, every other point at the point.
  void gatherContactLoads(const GeometryContact& c, int self);
  /// The line load from A to B (height-field frame): force F with resultant at tF, stiffness K with centroid at
  /// tK (t in [0, 1] from A to B), each a non-negative linear density, integrated against the weights exactly.
  void spreadLine(const Vec3& A, const Vec3& B, Real F, Real tF, Real K, Real tK);
  std::vector<VertexLoad> lastLoads_;
  // --- end line loads ---
  /// Lowers vertex v by dz > 0 as compression: height, c (and m), and the ledger's heightField -> compressed.
  void compressVertex(size_t v, Real dz, Real newMultiplier, Real dc);
  /// Books direct HeightField edits (dirty rectangle) into the heightField account.
  void reconcileExternalEdits() const;
  MaterialRef defaultMaterial() const;

  GeometryRef geometry_;
  HeightFieldRef heightField_;
  std::unique_ptr<TerrainDataInterface> data_;
  std::shared_ptr<ContactListener> contactListener_;
  std::shared_ptr<StepListener> stepListener_;
  bool lockedBorders_ = false;
  bool avalancheMassLoss_ = true;
  size_t nx_ = 0, ny_ = 0;
  Real dx_ = 0, dy_ = 0;
  mutable TerrainVolumeLedger ledger_;
  // Sparse per-step load gathering: load_ is dense (zero between steps), loaded_ lists the vertices written.
  std::vector<Real> load_;
  std::vector<Real> avgLoad_, avgStiff_;  ///< load averaged over loadAveragingTime_ (N, N/m)
  std::vector<size_t> active_;           ///< vertices with a non-zero average
  Real loadAveragingTime_ = defaultLoadAveragingTime;
  std::vector<Real> stiffness_;  ///< N/m: barycentric share of the contact points' Young's moduli
  std::vector<size_t> loaded_;
  size_t numLoaded_ = 0, numYielded_ = 0;
  double lastContactTime_ = 0, lastPostTime_ = 0;
  double contactTimeAccum_ = 0;
  // Avalanches (terrain_avalanche.cpp).
  /// Arms the three vertices of a merged particle (and the extent around them); nothing while disabled.
  void armAvalancheAt(const size_t (&v)[3]);
  void armWithExtent(size_t v, int life);
  void arm(size_t v, int life);
  void avalancheStep();
  Real reposeTangent(size_t v) const;
  Real reposeAngle(size_t v) const;
  /// Moves soil between vertices a and b (8-neighbours, distance ell) as the file comment says; factor =
  /// 2 decay. Returns true when soil moved.
  bool relaxPair(size_t a, size_t b, Real ell, Real factor, TerrainAvalancheStats& stats);
  bool dynamicHeightField_ = false;
  int avalancheLifeTime_ = defaultAvalancheStepLifeTime;
  Real avalancheDecay_ = defaultAvalancheDecayPercent;
  int avalancheExtent_ = defaultAvalancheVertexDistanceExtent;
  Real wetness_ = 0;
  std::vector<int> life_;            ///< per vertex: avalanche passes left (0: not armed)
  std::vector<uint8_t> inList_;      ///< per vertex: 1 listed in armed_, 2 visited in the running pass
  std::vector<size_t> armed_;        ///< the armed vertices (sparse)
  TerrainAvalancheStats avalancheStats_;
  double lastAvalancheTime_ = 0;
  class EditBatch;
  EditBatch* editBatch_ = nullptr;   ///< the open batch of height edits while avalanches run
  double lastPreCollideTime_ = 0;  ///< s, the pre-collide listener (digging) of the last step
  // Dynamic height field: deformers (terrain_deform.cpp).
  struct DeformerOverlap;
  bool deformerOverlap(const Geometry& g, DeformerOverlap& o) const;
  void modifyDeformerContact(GeometryContact& c, int self);
  void deformStep();
  Real scalerV_ = defaultVerticalYoungsModulusAreaScaler, scalerH_ = defaultHorizontalYoungsModulusAreaScaler;
  Real cutOffV_ = defaultDynamicHeightFieldCutOffVelocity, cutOffW_ = defaultDynamicHeightFieldCutOffAngularVelocity;
  std::vector<DeformerContactInfo> deformerContacts_, lastDeformerContacts_;
  DeformStats deformStats_;
  // Digging.
  Real minDigAngle_ = 3.14159265358979323846 / 10;
  Real mergeVelocity_ = 0.1;
  bool failureWedge_ = false;  // setShovelFailureWedge (issue 16, FEE)
  TerrainParticleAttributes particleAttributes_{*this};
  std::vector<Real> pending_;                              ///< per vertex, m^3
  std::vector<std::pair<size_t, Real>> particles_;        ///< live terrain particles: id, carried volume
  std::vector<const Geometry*> reportedBadShovels_;       ///< logged once each
  struct ParticleMaterialCache {
    const Material* source = nullptr;
    Real radius = 0, adhesion = 0, density = 0;
    MaterialRef material;
    // Particle contact materials (terrain_particle_materials.cpp).
    MaterialRef sourceRef;                                       ///< keeps source alive for its parameters
    ContactMaterialRef self;                                     ///< (material, material)
    std::vector<std::pair<MaterialRef, ContactMaterialRef>> external;  ///< (external material, its contact)
    ContactMaterialRef ground;  ///< DIRECT mode: (material, terrain geometry's material), ITERATIVE; else null
    MaterialRef groundMaterial;
  };
  std::vector<ParticleMaterialCache> particleMaterials_;
  TerrainDigStats digStats_;
  // --- shovel read-outs and ground cutting force (terrain_shovel.cpp) ---------------------------------------
  void updateShovelStats();
  /// Contact listener part: the ground cutting force on a shovel-terrain contact (TerrainDataInterface).
  void applyGroundCuttingForce(GeometryContact& contact, const Geometry& other);
  std::vector<TerrainShovelStats> shovelStats_;
  /// The ground cutting rows of shovels that are deformers (one per shovel geometry; terrain_shovel.cpp).
  class CuttingConstraint;
  std::vector<std::shared_ptr<CuttingConstraint>> cutting_;
  // --- end shovel read-outs ----------------------------------------------------------------------------------
  // Particle contact materials (terrain_particle_materials.cpp).
  std::vector<const Material*> warnedMaterials_;  ///< the FAQ warning, logged once per material
};
using TerrainRef = std::shared_ptr<Terrain>;

}  // namespace scree

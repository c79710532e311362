// One function per section (one file each in this folder); sections.cpp lists them in report order.
#pragma once

#include "../report.h"

namespace report {

Section lightningSection();       // lightning.cpp
Section lightning3dSection();     // lightning3d.cpp
Section lightningShapeSection();  // lightning_shape.cpp
Section fogTablesSection();       // fog_tables.cpp
Section fogHeightMarchSection();  // fog_height_march.cpp
Section fogConventionsSection();  // fog_conventions.cpp
Section tangentsSection();        // tangents.cpp
Section thinFilmSection();        // thin_film.cpp
Section glowSection();            // glow.cpp
Section renderBubbleSection();    // render_bubble.cpp
Section renderFogSection();       // render_fog.cpp
Section renderLightningSection(); // render_lightning.cpp

}  // namespace report

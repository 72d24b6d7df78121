# hiltwin_add_20sim_plant: one CMake line turns a folder of 20-sim generated C++ class code into
# a plant that `hiltwin run --plant NAME` finds (docs/20sim.md). Written in full with the
# adapter (plant/include/hiltwin/plant/twentysim_plant.h).

set terminal pngcairo size 900,600
set output 'peers.png'
set logscale xy
set grid
set xlabel 'whole-process time (s), 2 cores, llvmpipe'
set ylabel 'rel. RMSE of 8x8 means vs reference, noise in (%)'
set key outside right
plot 'peers.dat' index 0 with linespoints lw 2 pt 7 title 'veil, smoke', 'peers.dat' index 1 with linespoints lw 2 pt 5 dt 2 title 'vdb\_render, smoke', 'peers.dat' index 2 with linespoints lw 2 pt 7 title 'veil, sphere', 'peers.dat' index 3 with linespoints lw 2 pt 5 dt 2 title 'vdb\_render, sphere', 'peers.dat' index 4 with linespoints lw 2 pt 7 title 'veil, plume', 'peers.dat' index 5 with linespoints lw 2 pt 5 dt 2 title 'vdb\_render, plume'

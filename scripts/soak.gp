# scripts/soak's picture of soak.csv: gnuplot -e "csv='..'; png='..'; loop=SECONDS" scripts/soak.gp
set datafile separator ','
set terminal pngcairo size 1200,1000 font 'sans,10'
set output png
set multiplot layout 4,1 title 'semap-onboard soak (simulated rig, loops drive)'
set key autotitle columnhead top left
set grid
set xlabel 'drive time (min)'
set arrow 1 from loop/60.0, graph 0 to loop/60.0, graph 1 nohead dashtype 2
set ylabel 'MiB'
plot csv using ($1/60):2 with lines lw 2 title 'RSS', \
     csv using ($1/60):4 with lines lw 2 title 'checkpoint log'
set ylabel 'CPU %'
plot csv using ($1/60):3 with lines title 'semap-onboard CPU (100 = one core)', \
     csv using ($1/60):($11*100) with lines title 'machine load1 x 100'
set ylabel 'ms'
plot csv using ($1/60):7 with lines title 'perception p50', \
     csv using ($1/60):8 with lines title 'perception p99', \
     csv using ($1/60):9 with lines title 'mapping p50', \
     csv using ($1/60):10 with lines title 'mapping p99'
set ylabel 'count'
plot csv using ($1/60):5 with lines lw 2 title 'drops in health (rings and stages, total)', \
     csv using ($1/60):6 with lines lw 2 title 'checkpoint failures'
unset multiplot

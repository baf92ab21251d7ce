# speed_error.png, made by bench/report_speed_error (its data: speed_error.csv):
#   build/bench/report_speed_error --repeats 3 --out bench/results examples/rolling_disk/rolling_disk.urdf examples/sleigh/sleigh.urdf examples/hemisphere_bowl/hemisphere_bowl.urdf
set datafile separator ','
set terminal pngcairo size 1100,600 noenhanced
set output 'bench/results/speed_error.png'
set logscale xy
set format y '1e%L'
set format x '1e%L'
set xlabel 'wall time per simulated second [s]'
set ylabel 'max state error at t = 2 s'
set key outside right
set grid
set title 'appell: speed against error (tree solver, projection on)'
scenes = 'rolling_disk sleigh hemisphere_bowl'
methods = 'euler rk4 dopri5 dop853'
plot for [i=1:words(scenes)*4] 'bench/results/speed_error.csv' using ((strcol(1) eq word(scenes, (i-1)/4+1) && strcol(2) eq word(methods, (i-1)%4+1)) ? $5 : 1/0):6 with linespoints lc (i-1)%4+1 pt (i-1)/4+4 title word(methods, (i-1)%4+1).' / '.word(scenes, (i-1)/4+1)

# Work–precision figure of bench/results/peers.md; made by bench/peers/report_peers:
#   build/bench/peers/report_peers --repeats 3 --out bench/results
set datafile separator ','
set terminal pngcairo size 1500,560 noenhanced
set output 'bench/results/peers.png'
set logscale xy
set format y '1e%L'
set format x '1e%L'
set grid
set xlabel 'CPU time per simulated second [s]'
set ylabel 'centre position error at t = 10 s [m]'
set key outside right
methods = 'appell/dopri5 appell/dop853 appell/rk4 appell/dopri5-cylinder simbody/merson simbody/rk3 mujoco/euler mujoco/euler-noslip'
eng(i) = substr(word(methods,i), 1, strstrt(word(methods,i),'/')-1)
met(i) = substr(word(methods,i), strstrt(word(methods,i),'/')+1, strlen(word(methods,i)))
set multiplot layout 1,2
unset key
set title 'rolling disk, case spin'
plot for [i=1:words(methods)] 'bench/results/peers.csv' using ((strcol(1) eq 'spin' && strcol(2) eq eng(i) && strcol(3) eq met(i) && $11 > 0) ? $8/1000 : 1/0):11 with linespoints lw 2 pt i title word(methods,i)
set key
set title 'rolling disk, case steady'
plot for [i=1:words(methods)] 'bench/results/peers.csv' using ((strcol(1) eq 'steady' && strcol(2) eq eng(i) && strcol(3) eq met(i) && $11 > 0) ? $8/1000 : 1/0):11 with linespoints lw 2 pt i title word(methods,i)
unset multiplot

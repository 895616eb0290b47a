//! The coefficients of RODAS5P (Steinebach 2023) and RODAS4 (Hairer & Wanner), in the
//! transformed form of HNW II §IV.7 (7.25) that Hairer's `rodas.f` and OrdinaryDiffEq.jl use:
//! stage arguments `a_ij`, stage couplings `C_ij` (entering as `C_ij / h`), stage times `c_i`,
//! `f_t` weights `d_i` (= `gamma_i`) and the dense-output matrix `H`.
//!
//! Sources: RODAS5P: G. Steinebach, "Construction of Rosenbrock–Wanner method Rodas5P and
//! numerical benchmarks within the Julia Differential Equations package", BIT Numer. Math. 63
//! (2023) 27, with the digits as published in OrdinaryDiffEq.jl (`Rodas5PTableau`, whose author
//! is Steinebach). RODAS4: E. Hairer & G. Wanner, *Solving ODEs II*, 2nd ed. 1996, §VI.4 and
//! `rodas.f` (METH = 1), as in OrdinaryDiffEq.jl's `Rodas4Tableau`. The digits are printed to
//! 16-17 significant figures (hence `excessive_precision`); the tests check the order
//! conditions and the stability function from them.
//!
//! Both methods are stiffly accurate with the same tail: the stage after the last one with
//! `c_i < 1` evaluates `f` at `y + sum_j a_ij u_j` (`t + h`), and every further stage at the
//! previous stage's argument plus the previous stage (`a_{i+1, j} = a_ij + delta_{j, i}`), the
//! solution being the last argument plus the last stage; the last stage is the error estimate
//! (the embedded solution is the last stage's argument).
#![allow(clippy::excessive_precision)]

/// Most stages of a tableau here.
pub(crate) const MAX_STAGES: usize = 8;

/// A Rosenbrock method in the transformed form (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Tableau {
    pub name: &'static str,
    pub stages: usize,
    /// Order of the solution and of the embedded solution (the error estimate is
    /// `O(h^(embedded + 1))`).
    pub order: u32,
    pub embedded_order: u32,
    pub gamma: f64,
    /// Stage arguments `y + sum_j a[i][j] u_j` (strictly lower).
    pub a: [[f64; MAX_STAGES]; MAX_STAGES],
    /// Couplings `C_ij` (strictly lower).
    pub c_ij: [[f64; MAX_STAGES]; MAX_STAGES],
    /// Stage times `t + c[i] h` and `f_t` weights `d[i]`.
    pub c: [f64; MAX_STAGES],
    pub d: [f64; MAX_STAGES],
    /// Solution `y + sum_j m[j] u_j`; the error estimate is the last stage.
    pub m: [f64; MAX_STAGES],
    /// Dense output: `dense` rows of `H` (each `sum_j H[k][j] u_j`).
    pub dense: usize,
    pub h: [[f64; MAX_STAGES]; 3],
}

/// Lower-triangular rows from their nonzero prefixes.
const fn lower<const N: usize>(rows: [&[f64]; N]) -> [[f64; MAX_STAGES]; MAX_STAGES] {
    let mut out = [[0.0; MAX_STAGES]; MAX_STAGES];
    let mut i = 0;
    while i < N {
        let mut j = 0;
        while j < rows[i].len() {
            out[i][j] = rows[i][j];
            j += 1;
        }
        i += 1;
    }
    out
}

/// The stiffly accurate tail (module docs): rows `first + 1 ..= stages - 1` of `a` from row
/// `first`, and `m` = the last row plus the last stage.
const fn with_tail(mut t: Tableau, first: usize) -> Tableau {
    let s = t.stages;
    let mut i = first + 1;
    while i < s {
        t.a[i] = t.a[i - 1];
        t.a[i][i - 1] += 1.0;
        t.c[i] = 1.0;
        i += 1;
    }
    t.m = t.a[s - 1];
    t.m[s - 1] += 1.0;
    t
}

/// RODAS5P: 8 stages, order 5(4), L-stable, stiffly accurate, dense output of order 4.
pub(crate) const RODAS5P: Tableau = with_tail(
    Tableau {
        name: "RODAS5P",
        stages: 8,
        order: 5,
        embedded_order: 4,
        gamma: 0.21193756319429014,
        a: lower([
            &[],
            &[3.0],
            &[2.849394379747939, 0.45842242204463923],
            &[-6.954028509809101, 2.489845061869568, -10.358996098473584],
            &[2.8029986275628964, 0.5072464736228206, -0.3988312541770524, -0.04721187230404641],
            &[-7.502846399306121, 2.561846144803919, -11.627539656261098, -0.18268767659942256, 0.030198172008377946],
        ]),
        c_ij: lower([
            &[],
            &[-14.155112264123755],
            &[-17.97296035885952, -2.859693295451294],
            &[147.12150275711716, -1.41221402718213, 71.68940251302358],
            &[165.43517024871676, -0.4592823456491126, 42.90938336958603, -5.961986721573306],
            &[24.854864614690072, -3.0009227002832186, 47.4931110020768, 5.5814197821558125, -0.6610691825249471],
            &[30.91273214028599, -3.1208243349937974, 77.79954646070892, 34.28646028294783, -19.097331116725623, -28.087943162872662],
            &[37.80277123390563, -3.2571969029072276, 112.26918849496327, 66.9347231244047, -40.06618937091002, -54.66780262877968, -9.48861652309627],
        ]),
        c: [0.0, 0.6358126895828704, 0.4095798393397535, 0.9769306725060716, 0.4288403609558664, 1.0, 1.0, 1.0],
        d: [0.21193756319429014, -0.42387512638858027, -0.3384627126235924, 1.8046452872882734, 2.325825639765069, 0.0, 0.0, 0.0],
        m: [0.0; MAX_STAGES],
        dense: 3,
        h: [
            [25.948786856663858, -2.5579724845846235, 10.433815404888879, -2.3679251022685204, 0.524948541321073, 1.1241088310450404, 0.4272876194431874, -0.17202221070155493],
            [-9.91568850695171, -0.9689944594115154, 3.0438037242978453, -24.495224566215796, 20.176138334709044, 15.98066361424651, -6.789040303419874, -6.710236069923372],
            [11.419903575922262, 2.8879645146136994, 72.92137995996029, 80.12511834622643, -52.072871366152654, -59.78993625266729, -0.15582684282751913, 4.883087185713722],
        ],
    },
    5,
);

/// RODAS4: 6 stages, order 4(3), L-stable, stiffly accurate, dense output of order 3.
pub(crate) const RODAS4: Tableau = with_tail(
    Tableau {
        name: "RODAS4",
        stages: 6,
        order: 4,
        embedded_order: 3,
        gamma: 0.25,
        a: lower([
            &[],
            &[1.544],
            &[0.9466785280815826, 0.2557011698983284],
            &[3.314825187068521, 2.896124015972201, 0.9986419139977817],
            &[1.221224509226641, 6.019134481288629, 12.53708332932087, -0.6878860361058950],
        ]),
        c_ij: lower([
            &[],
            &[-5.6688],
            &[-2.430093356833875, -0.2063599157091915],
            &[-0.1073529058151375, -9.594562251023355, -20.47028614809616],
            &[7.496443313967647, -10.24680431464352, -33.99990352819905, 11.70890893206160],
            &[8.083246795921522, -7.981132988064893, -31.52159432874371, 16.31930543123136, -6.058818238834054],
        ]),
        c: [0.0, 0.386, 0.21, 0.63, 1.0, 1.0, 0.0, 0.0],
        d: [0.25, -0.1043, 0.1035, -0.03620000000000023, 0.0, 0.0, 0.0, 0.0],
        m: [0.0; MAX_STAGES],
        dense: 2,
        h: [
            [10.12623508344586, -7.487995877610167, -34.80091861555747, -7.992771707568823, 1.025137723295662, 0.0, 0.0, 0.0],
            [-0.6762803392801253, 6.087714651680015, 16.43084320892478, 24.76722511418386, -6.594389125716872, 0.0, 0.0, 0.0],
            [0.0; MAX_STAGES],
        ],
    },
    4,
);

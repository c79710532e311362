// The C API (effects/effects.h) from C# through P/Invoke, as a Unity script would call it:
// one bolt and one fog table, printed in the form `capi_test --print` prints them, for
// tests/capi/ffi_test.sh to compare. The structs mirror the header's field for field
// (sequential layout; C enums are ints, size_t is UIntPtr on 64-bit Linux).
//   mcs Effects.cs -out:effects_ffi.exe && LD_LIBRARY_PATH=<dir of libeffects.so> mono effects_ffi.exe
using System;
using System.Globalization;
using System.Runtime.InteropServices;
using System.Text;

static class Native {
  const string Lib = "effects";  // as Unity names it: libeffects.so here, effects.dll on Windows

  [StructLayout(LayoutKind.Sequential)]
  public struct BoltParams {
    public UIntPtr size;
    public int width, height, depth;
    [MarshalAs(UnmanagedType.ByValArray, SizeConst = 3)] public int[] start;
    public IntPtr targets;
    public UIntPtr targetCount;
    public IntPtr obstacles, targetRegion;
    public int method;
    public double eta;
    public int neighbourhood;
    public ulong seed;
    public UIntPtr maxSteps;
    public int calibrated;
    public double axisGrowth;
    public int lifetime;
  }

  [StructLayout(LayoutKind.Sequential)]
  public struct Fog {
    public UIntPtr size;
    public int type, convention;
    [MarshalAs(UnmanagedType.ByValArray, SizeConst = 3)] public double[] color;
    public double visibilityRange, start, end, density, distanceCoefficient, peak, heightFalloff, baseHeight;
    [MarshalAs(UnmanagedType.ByValArray, SizeConst = 3)] public double[] extinction;
    [MarshalAs(UnmanagedType.ByValArray, SizeConst = 3)] public double[] inscattering;
    public double startDistance, maxOpacity, cutoffDistance;
    public int hasSecondLayer;
    public double secondDensity, secondHeightFalloff, secondBaseHeight;
    public int hasDirectional;
    [MarshalAs(UnmanagedType.ByValArray, SizeConst = 3)] public double[] directionalColor;
    [MarshalAs(UnmanagedType.ByValArray, SizeConst = 3)] public double[] directionalDirection;
    public double directionalG, directionalExponent, directionalStartDistance;
  }

  [StructLayout(LayoutKind.Sequential)]
  public struct TableOptions {
    public UIntPtr size, columns;
    public double maxError;
    public UIntPtr maxSize;
    public double rangeStart, rangeEnd;
    public UIntPtr elevations;
    public double cameraHeight;
    public int layout;
  }

  [DllImport(Lib)] public static extern void effects_bolt_params_defaults(ref BoltParams p);
  [DllImport(Lib)] public static extern int effects_bolt_grow(ref BoltParams p, out IntPtr bolt, out IntPtr error);
  [DllImport(Lib)] public static extern UIntPtr effects_bolt_node_count(IntPtr bolt);
  [DllImport(Lib)] public static extern IntPtr effects_bolt_cells(IntPtr bolt);
  [DllImport(Lib)] public static extern void effects_bolt_free(IntPtr bolt);
  [DllImport(Lib)] public static extern void effects_fog_defaults(ref Fog f);
  [DllImport(Lib)] public static extern void effects_fog_table_options_defaults(ref TableOptions o);
  [DllImport(Lib)] public static extern int effects_fog_table_build(ref Fog f, ref TableOptions o, out IntPtr table, out IntPtr error);
  [DllImport(Lib)] public static extern UIntPtr effects_fog_table_width(IntPtr table);
  [DllImport(Lib)] public static extern IntPtr effects_fog_table_factor(IntPtr table);
  [DllImport(Lib)] public static extern void effects_fog_table_free(IntPtr table);
  [DllImport(Lib)] public static extern IntPtr effects_error_field(IntPtr error);
  [DllImport(Lib)] public static extern IntPtr effects_error_message(IntPtr error);
  [DllImport(Lib)] public static extern void effects_error_free(IntPtr error);
  [DllImport(Lib)] public static extern IntPtr effects_version();
}

static class Program {
  static void Check(int status, IntPtr error, string what) {
    if (status == 0) return;
    string field = Marshal.PtrToStringAnsi(Native.effects_error_field(error));
    string message = Marshal.PtrToStringAnsi(Native.effects_error_message(error));
    Native.effects_error_free(error);
    throw new Exception(what + ": " + field + " " + message);
  }

  static int Main(string[] args) {
    var inv = CultureInfo.InvariantCulture;
    var p = new Native.BoltParams();
    Native.effects_bolt_params_defaults(ref p);
    if ((ulong)p.size != (ulong)Marshal.SizeOf(typeof(Native.BoltParams)))
      throw new Exception("effects_bolt_params is " + p.size + " bytes in C, " + Marshal.SizeOf(typeof(Native.BoltParams)) + " here");
    p.width = p.height = 48;
    p.start = new int[] {24, 0, 0};
    int[] target = {24, 47, 0};
    var pinned = GCHandle.Alloc(target, GCHandleType.Pinned);
    p.targets = pinned.AddrOfPinnedObject();
    p.targetCount = (UIntPtr)1;
    p.seed = 3;
    IntPtr bolt, error;
    Check(Native.effects_bolt_grow(ref p, out bolt, out error), error, "bolt");
    pinned.Free();
    int n = (int)(ulong)Native.effects_bolt_node_count(bolt);
    var cells = new int[3 * n];
    Marshal.Copy(Native.effects_bolt_cells(bolt), cells, 0, 3 * n);
    Native.effects_bolt_free(bolt);
    var line = new StringBuilder("bolt");
    foreach (int c in cells) line.Append(' ').Append(c.ToString(inv));
    Console.WriteLine(line);

    var fog = new Native.Fog();
    Native.effects_fog_defaults(ref fog);
    if ((ulong)fog.size != (ulong)Marshal.SizeOf(typeof(Native.Fog))) throw new Exception("effects_fog's size differs");
    fog.type = 3;  // EFFECTS_FOG_GL_EXP
    fog.density = 0.05;
    var o = new Native.TableOptions();
    Native.effects_fog_table_options_defaults(ref o);
    if ((ulong)o.size != (ulong)Marshal.SizeOf(typeof(Native.TableOptions))) throw new Exception("effects_fog_table_options' size differs");
    o.columns = (UIntPtr)64;
    o.rangeStart = 0;
    o.rangeEnd = 100;
    IntPtr table;
    Check(Native.effects_fog_table_build(ref fog, ref o, out table, out error), error, "fog table");
    int w = (int)(ulong)Native.effects_fog_table_width(table);
    var factor = new float[w];
    Marshal.Copy(Native.effects_fog_table_factor(table), factor, 0, w);
    Native.effects_fog_table_free(table);
    line = new StringBuilder("fog");
    // %.9g as C prints it: nine significant digits, then the shortest form C's printf would use.
    foreach (float f in factor) line.Append(' ').Append(((double)f).ToString("G9", inv).Replace("E-0", "e-0").Replace("E-", "e-"));
    Console.WriteLine(line);
    Console.Error.WriteLine("C# via P/Invoke: libeffects " + Marshal.PtrToStringAnsi(Native.effects_version()) + ", " + n + " cells, " + w + " fog entries");
    return 0;
  }
}
